// The upright tool's culling tests never cull what the BSP calls penetrating.
#include <random>

#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/geometry/upright_tool.hpp"
#include "tests/support/sample_tools.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;
using stencil::test::kSampleTools;

TEST_GROUP(UprightTool){};

TEST(UprightTool, NeverCullsAPointOrABoxHoldingAPointThatPenetrates) {
  std::mt19937_64 random(71);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    // Points in a box a little larger than the tool, boxes up to a tenth of its size around them.
    const double reach = 1.2 * tool.envelope.holder_radius_mm;
    const double height = tool.envelope.total_length_mm;
    const auto across = [&](std::mt19937_64& r) { return reach * unit(r); };
    const auto along = [&](std::mt19937_64& r) { return 0.5 * height + 0.6 * height * unit(r); };
    const auto size = [&](std::mt19937_64& r) { return 0.05 * height * (1.0 + unit(r)); };
    const Eigen::Vector3d tip(3.0, -2.0, 1.0);
    int penetrating = 0;
    int culled_outside = 0;
    for (int i = 0; i < 40000; ++i) {
      const Eigen::Vector3d local(across(random), across(random), along(random));
      const PointClassification c = classify_in_tool_frame(tool, local);
      const bool point_may = upright_point_may_be_inside(tool, local, 0.0);
      const Eigen::Vector3d low = tip + local - Eigen::Vector3d(size(random), size(random), size(random));
      const Eigen::Vector3d high = tip + local + Eigen::Vector3d(size(random), size(random), size(random));
      const bool box_may = upright_box_may_touch(tool, tip, low, high, 0.0);
      if (c.contact == PointContact::Penetrating) {
        ++penetrating;
        CHECK_TEXT(point_may, sample.name);
        CHECK_TEXT(box_may, sample.name);
      } else if (!point_may) {
        ++culled_outside;
      }
    }
    // And they do cull: most points outside never reach the BSP.
    CHECK_TEXT(penetrating > 1000 && culled_outside > 20000, sample.name);
  }
}
