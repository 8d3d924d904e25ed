// The tool notation: defaults, and a clear refusal of anything else.
#include <string>

#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/tool_option.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;
using stencil::geometry::CutterKind;

namespace {

std::string error_of(const std::string& tool, const std::string& holder = "") {
  try {
    static_cast<void>(parse_tool(tool, holder));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_GROUP(ToolOption){};

TEST(ToolOption, BallWithDefaultFlutesAndHolder) {
  const auto spec = parse_tool("ball:d=3", "");
  CHECK(spec.kind == CutterKind::Ball);
  DOUBLES_EQUAL(3.0, spec.diameter_mm, 0.0);
  DOUBLES_EQUAL(12.0, spec.flute_length_mm, 0.0);
  DOUBLES_EQUAL(10.0, spec.holder_diameter_mm, 0.0);
  DOUBLES_EQUAL(20.0, spec.holder_length_mm, 0.0);
}

TEST(ToolOption, BullNoseWithFlutesAndAHolder) {
  const auto spec = parse_tool("bull:d=6,r=1,l=9", "d=8,l=15");
  CHECK(spec.kind == CutterKind::BullNose);
  DOUBLES_EQUAL(1.0, spec.corner_radius_mm, 0.0);
  DOUBLES_EQUAL(9.0, spec.flute_length_mm, 0.0);
  DOUBLES_EQUAL(8.0, spec.holder_diameter_mm, 0.0);
  DOUBLES_EQUAL(15.0, spec.holder_length_mm, 0.0);
}

TEST(ToolOption, RefusesWhatItDoesNotUnderstand) {
  CHECK(error_of("drill:d=3").find("expected flat:d=D") != std::string::npos);
  CHECK(error_of("ball").find("the diameter d=D is required") != std::string::npos);
  CHECK(error_of("ball:d=3,r=1").find("unknown key 'r'") != std::string::npos);
  CHECK(error_of("bull:d=3").find("corner radius r=RC") != std::string::npos);
  CHECK(error_of("ball:d=3,d=4").find("given twice") != std::string::npos);
  CHECK(error_of("ball:d=three").find("d='three': expected a finite number") != std::string::npos);
  CHECK(error_of("ball:d=nan").find("expected a finite number") != std::string::npos);
  CHECK(error_of("ball:d=3", "d=10,x=2").find("--holder: unknown key 'x'") != std::string::npos);
  CHECK(error_of("ball:d=3", "10").find("--holder: '10': expected key=value") != std::string::npos);
}
