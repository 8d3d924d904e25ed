// The STL reader: both formats, the binary-that-says-solid trap, and errors that name the place.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/stl_reader.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;

namespace {

std::vector<std::byte> bytes_of(const std::string& text) {
  std::vector<std::byte> bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
}

// The message parse_stl throws, or "" when it parses.
std::string error_of(const std::vector<std::byte>& bytes) {
  try {
    static_cast<void>(parse_stl(bytes, "part.stl"));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

void check_error(const std::vector<std::byte>& bytes, const std::string& expected_fragment) {
  const std::string message = error_of(bytes);
  CHECK_TEXT(message.find("part.stl") != std::string::npos, message.c_str());
  CHECK_TEXT(message.find(expected_fragment) != std::string::npos, message.c_str());
}

const std::string kOneFacet =
    "solid one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
    "  endloop\n endfacet\nendsolid one\n";

}  // namespace

TEST_GROUP(StlReader){};

TEST(StlReader, ReadsAsciiAndBinaryAlike) {
  const auto facets = hexagonal_prism(8.0, 6.0, 25.0, 12.5);
  const StlMesh ascii = parse_stl(encode_stl(facets, false, "hex"), "hex.stl");
  const StlMesh binary = parse_stl(encode_stl(facets, true, "hex"), "hex.stl");
  CHECK(ascii.format == StlFormat::Ascii);
  CHECK(binary.format == StlFormat::Binary);
  LONGS_EQUAL(facets.size(), ascii.triangles.size());
  LONGS_EQUAL(facets.size(), binary.triangles.size());
  for (std::size_t t = 0; t < facets.size(); ++t) {
    for (std::size_t v = 0; v < 3; ++v) {
      CHECK((ascii.triangles[t].vertices[v] - facets[t][v]).norm() < 1e-7);
      CHECK((binary.triangles[t].vertices[v] - facets[t][v]).norm() < 1e-5);
    }
  }
}

TEST(StlReader, ABinaryFileThatBeginsWithSolidIsStillBinary) {
  auto bytes = encode_stl(hexagonal_prism(8.0, 6.0, 25.0, 12.5), true, "hex");
  std::memcpy(bytes.data(), "solid hex made by a careless exporter", 37);
  const StlMesh mesh = parse_stl(bytes, "part.stl");
  CHECK(mesh.format == StlFormat::Binary);
  LONGS_EQUAL(24, mesh.triangles.size());
}

TEST(StlReader, ReadsEverySolidOfAnAsciiFile) {
  const StlMesh mesh = parse_stl(bytes_of(kOneFacet + kOneFacet + kOneFacet), "part.stl");
  LONGS_EQUAL(3, mesh.solid_count);
  LONGS_EQUAL(3, mesh.triangles.size());
}

TEST(StlReader, RefusesAnEmptyFile) { check_error({}, "empty"); }

TEST(StlReader, RefusesATruncatedBinaryFileSayingWhatTheSizeShouldBe) {
  auto bytes = encode_stl(hexagonal_prism(8.0, 6.0, 25.0, 12.5), true, "hex");
  bytes.resize(bytes.size() - 7);
  check_error(bytes, "24 triangles, which needs 1284 bytes, but the file has 1277");
}

TEST(StlReader, RefusesATriangleCountThatDisagreesWithTheSize) {
  auto bytes = encode_stl(hexagonal_prism(8.0, 6.0, 25.0, 12.5), true, "hex");
  const std::uint32_t wrong = 25;
  std::memcpy(bytes.data() + 80, &wrong, sizeof(wrong));
  check_error(bytes, "25 triangles");
}

TEST(StlReader, RefusesAShortFileThatIsNotAscii) { check_error(bytes_of("hello"), "too short for a binary STL"); }

TEST(StlReader, RefusesANonFiniteBinaryCoordinateNamingFacetVertexAndByte) {
  auto bytes = encode_stl(hexagonal_prism(8.0, 6.0, 25.0, 12.5), true, "hex");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bytes.data() + 84 + 50 * 7 + 12 + 12 * 2 + 4, &nan, sizeof(nan));  // facet 7, vertex 2, y
  check_error(bytes, "facet 7 (byte 470): vertex 2 has a non-finite coordinate");
}

TEST(StlReader, RefusesNonFiniteAsciiNumbersNamingTheLine) {
  std::string text = kOneFacet;
  text.replace(text.find("vertex 1 0 0"), 12, "vertex 1 inf 0");
  check_error(bytes_of(text), "line 5: a vertex coordinate is not finite (inf)");
  text = kOneFacet;
  text.replace(text.find("vertex 0 1 0"), 12, "vertex 0 nan 0");
  check_error(bytes_of(text), "line 6:");
}

TEST(StlReader, RefusesAsciiSyntaxErrorsNamingTheLineAndWhatWasExpected) {
  std::string text = kOneFacet;
  text.replace(text.find("outer loop"), 10, "outer lop");
  check_error(bytes_of(text), "line 3: expected 'loop', found 'lop'");
  text = kOneFacet;
  text.replace(text.find("vertex 1 0 0"), 12, "vertex 1 0 x");
  check_error(bytes_of(text), "line 5: expected a number for a vertex coordinate, found 'x'");
  check_error(bytes_of(kOneFacet.substr(0, kOneFacet.find("endloop"))), "expected 'endloop', found the end of the file");
  check_error(bytes_of("solid a\n facet normal 0 0 1\n"), "expected 'outer', found the end of the file");
  check_error(bytes_of("solid a\n"), "the file ends inside a solid");
  check_error(bytes_of(kOneFacet + "garbage\n"), "line 10: expected 'solid', found 'garbage'");
}
