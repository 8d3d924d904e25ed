// Which points a vertical tool can reach (toolchain/tablegen/reachability): the tip that puts the
// tool's surface on a point along its normal (none for a downward normal), and a point marked
// reachable only when that tip is inside the workspace and no other point lies deeper than the
// tolerance inside the tool there; the same marks whatever the threads.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/tables/table_format.hpp"
#include "toolchain/tablegen/bvh_builder.hpp"
#include "toolchain/tablegen/reachability.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tablegen;

namespace {

constexpr geometry::ToolSpec kBall3{geometry::CutterKind::Ball, 3.0, 12.0, 0.0, 10.0, 20.0};
constexpr geometry::ToolSpec kFlat3{geometry::CutterKind::Flat, 3.0, 12.0, 0.0, 10.0, 20.0};

void check_tip(const Eigen::Vector3d& expected, const Eigen::Vector3d& tip) {
  DOUBLES_EQUAL(expected.x(), tip.x(), 1e-12);
  DOUBLES_EQUAL(expected.y(), tip.y(), 1e-12);
  DOUBLES_EQUAL(expected.z(), tip.z(), 1e-12);
}

// Points and normals in table order with their tree, and the tool: what mark_reachable is given.
struct Cloud {
  std::vector<tables::PackedPoint> points, normals;
  std::vector<tables::BvhNode> nodes;
  geometry::ToolBsp tool{};

  Cloud(const std::vector<tables::PackedPoint>& given_points, const std::vector<tables::PackedPoint>& given_normals) {
    const PointTree tree = build_point_tree(given_points, 1);
    for (const std::uint32_t i : tree.order) {
      points.push_back(given_points[i]);
      normals.push_back(given_normals[i]);
    }
    nodes = tree.nodes;
    CHECK_TRUE(geometry::build_tool_bsp(kBall3, tool).ok);
  }
  std::vector<std::uint8_t> marks(const Eigen::Vector3d& workspace, unsigned threads = 1) const {
    const ReachInput input{points, normals, nodes, tool, workspace};
    return mark_reachable(input, threads, [](double) {});
  }
  // The mark of the point at (x, y, z), wherever the tree put it.
  static std::uint8_t mark_at(const Cloud& cloud, const std::vector<std::uint8_t>& marks, float x, float y, float z) {
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
      if (cloud.points[i].x_mm == x && cloud.points[i].y_mm == y && cloud.points[i].z_mm == z) {
        return marks[i];
      }
    }
    FAIL("no such point");
    return 0;
  }
};

// A 20 x 20 mm floor at z = 5 from (10, 10) sampled every `step` mm, facing up.
void add_floor(std::vector<tables::PackedPoint>& points, std::vector<tables::PackedPoint>& normals, float step = 0.5f) {
  const int steps = static_cast<int>(20.0f / step);
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; j <= steps; ++j) {
      points.push_back({10.0f + step * static_cast<float>(i), 10.0f + step * static_cast<float>(j), 5.0f});
      normals.push_back({0.0f, 0.0f, 1.0f});
    }
  }
}

}  // namespace

TEST_GROUP(Reachability){};

TEST(Reachability, ABallTouchesAFloorWithItsTipAndAWallWithItsEquator) {
  Eigen::Vector3d tip;
  CHECK_TRUE(touching_tip(kBall3, {10.0, 5.0, 2.0}, {0.0, 0.0, 1.0}, tip));
  check_tip({10.0, 5.0, 2.0}, tip);
  // A wall facing +x: the sphere's centre 1.5 mm out from it, the tip 1.5 mm below the centre.
  CHECK_TRUE(touching_tip(kBall3, {10.0, 5.0, 2.0}, {1.0, 0.0, 0.0}, tip));
  check_tip({11.5, 5.0, 0.5}, tip);
}

TEST(Reachability, AFlatEndMillTouchesAWallWithItsCornerEdge) {
  Eigen::Vector3d tip;
  CHECK_TRUE(touching_tip(kFlat3, {10.0, 5.0, 2.0}, {0.0, -1.0, 0.0}, tip));
  check_tip({10.0, 3.5, 2.0}, tip);
  CHECK_TRUE(touching_tip(kFlat3, {10.0, 5.0, 2.0}, {0.0, 0.0, 1.0}, tip));
  check_tip({10.0, 5.0, 2.0}, tip);
}

TEST(Reachability, NoVerticalToolTouchesAFaceThatLooksDown) {
  Eigen::Vector3d tip;
  CHECK_FALSE(touching_tip(kBall3, {10.0, 5.0, 2.0}, {0.0, 0.0, -1.0}, tip));
  CHECK_FALSE(touching_tip(kFlat3, {10.0, 5.0, 2.0}, {0.6, 0.0, -0.8}, tip));
}

TEST(Reachability, AnOpenFloorIsReachableAndItsUndersideIsNot) {
  std::vector<tables::PackedPoint> points, normals;
  add_floor(points, normals);
  points.push_back({20.0f, 20.0f, 4.0f});  // under the floor, facing down
  normals.push_back({0.0f, 0.0f, -1.0f});
  const Cloud cloud(points, normals);
  const std::vector<std::uint8_t> marks = cloud.marks({50.0, 50.0, 25.0});
  CHECK_EQUAL(tables::kPointReachable, Cloud::mark_at(cloud, marks, 20.0f, 20.0f, 5.0f));
  CHECK_EQUAL(tables::kPointReachable, Cloud::mark_at(cloud, marks, 10.0f, 10.0f, 5.0f));
  CHECK_EQUAL(0, Cloud::mark_at(cloud, marks, 20.0f, 20.0f, 4.0f));
}

TEST(Reachability, APointUnderAnotherIsReachableOnlyWhereTheToolClearsIt) {
  std::vector<tables::PackedPoint> points, normals;
  add_floor(points, normals);
  // A post 3 mm tall at (20, 20): the floor right beside it cannot be reached by the 3 mm ball.
  points.push_back({20.0f, 20.0f, 8.0f});
  normals.push_back({0.0f, 0.0f, 1.0f});
  const Cloud cloud(points, normals);
  const std::vector<std::uint8_t> marks = cloud.marks({50.0, 50.0, 25.0});
  CHECK_EQUAL(tables::kPointReachable, Cloud::mark_at(cloud, marks, 20.0f, 20.0f, 8.0f));
  CHECK_EQUAL(0, Cloud::mark_at(cloud, marks, 20.5f, 20.0f, 5.0f));
  CHECK_EQUAL(tables::kPointReachable, Cloud::mark_at(cloud, marks, 25.0f, 20.0f, 5.0f));
  const ReachInput input{cloud.points, cloud.normals, cloud.nodes, cloud.tool, {50.0, 50.0, 25.0}};
  CHECK_TRUE(upright_tool_collides(input, {20.5, 20.0, 5.0}));
  CHECK_FALSE(upright_tool_collides(input, {25.0, 20.0, 5.0}));
}

TEST(Reachability, ATipOutsideTheWorkspaceIsNotReachable) {
  std::vector<tables::PackedPoint> points, normals;
  add_floor(points, normals);
  const Cloud cloud(points, normals);
  // The workspace ends at x = 20: the floor beyond it cannot be reached.
  const std::vector<std::uint8_t> marks = cloud.marks({20.0, 50.0, 25.0});
  CHECK_EQUAL(tables::kPointReachable, Cloud::mark_at(cloud, marks, 20.0f, 10.0f, 5.0f));
  CHECK_EQUAL(0, Cloud::mark_at(cloud, marks, 20.5f, 10.0f, 5.0f));
}

TEST(Reachability, TheMarksAreTheSameWhateverTheThreads) {
  // More points than one chunk of work (4096), so that both threads mark some.
  std::vector<tables::PackedPoint> points, normals;
  add_floor(points, normals, 0.25f);
  for (int k = 0; k < 5; ++k) {
    points.push_back({12.0f + 3.0f * static_cast<float>(k), 15.0f, 7.0f});
    normals.push_back({0.0f, 0.0f, 1.0f});
  }
  const Cloud cloud(points, normals);
  CHECK(cloud.points.size() > 4096U);
  const std::vector<std::uint8_t> one = cloud.marks({50.0, 50.0, 25.0}, 1);
  CHECK(one == cloud.marks({50.0, 50.0, 25.0}, 2));
  CHECK(std::count(one.begin(), one.end(), 0) > 0);  // the posts hide some of the floor
  CHECK(std::count(one.begin(), one.end(), tables::kPointReachable) > 0);
}
