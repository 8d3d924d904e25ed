// The contact query on the default part: force along the face normal with magnitude k*d, none in
// free space, legality, and touched triangles marked at the tool's pose.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "firmware/core/geometry/meridian_box.hpp"
#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/leaf_contacts.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"
#include "toolchain/tablegen/tool_option.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {

// The default part: a hexagonal prism (circumradius 8, height 6) centred at (25, 12.5) with a
// corner towards +x; its top face is z = 6 and one side face has the outward normal (cos 30, sin 30, 0)
// at the apothem 8 cos 30 deg from the axis.
constexpr double kTop_mm = 6.0;
const double kApothem_mm = 8.0 * std::cos(3.14159265358979323846 / 6.0);
const Eigen::Vector3d kSideNormal(std::cos(3.14159265358979323846 / 6.0), 0.5, 0.0);

ToolPose upright_at(double x, double y, double tip_z) { return {{x, y, tip_z}, Eigen::Vector3d::UnitZ()}; }

// The cloud samples the surface to the covering radius, so a rounded tool can sit up to the
// table's gouge bound deeper than the deepest sample shows.
void check_depth(const tables::PartTables& part, double true_depth, const ContactResult& result) {
  CHECK(result.max_depth_mm <= true_depth + 1e-5);
  CHECK(result.max_depth_mm >= true_depth - part.header.gouge_bound_mm - 1e-5);
}

// The default part's table for `tool_text` at a fixed spacing (the gouge bound's would ask for
// millions of points for a flat end); its bytes must outlive the tables loaded from them.
tablegen::TableBytes table_at_spacing(const char* tool_text, double spacing_mm) {
  tablegen::GeneratorOptions options = test::default_job_options(2);
  options.tool = tablegen::parse_tool(tool_text, "");
  options.spacing_mm = spacing_mm;
  options.force = true;
  return test::make_table(test::default_part(), options);
}

// A tip within `across` mm of the prism's side faces and edges (either side of the apothem), on
// even trials within `spread` mm of `top` (near the top face), on odd ones 0.5-5.5 mm up (low
// beside the side faces, so that the tool's partition planes, a ball's equator or a bull nose's
// corner top, cross the faces).
Eigen::Vector3d tip_near_the_faces(std::mt19937_64& random, int trial, double across, double top, double spread) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double angle = 3.14159265358979323846 * unit(random);
  const double radius = kApothem_mm + across * unit(random);
  const double height = trial % 2 == 0 ? top + spread * unit(random) : 3.0 + 2.5 * unit(random);
  return {25.0 + radius * std::cos(angle), 12.5 + radius * std::sin(angle), height};
}

}  // namespace

TEST_GROUP(ContactQuery) {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options());
  tables::PartTables part{};
  ContactParameters parameters{};
  void setup() override { CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok); }
};

TEST(ContactQuery, NoForceInFreeSpace) {
  const ContactResult result = query_contacts(part, upright_at(25.0, 12.5, kTop_mm + 0.5), parameters);
  CHECK(result.status == QueryStatus::Ok);
  LONGS_EQUAL(0, result.penetrating_points);
  DOUBLES_EQUAL(0.0, result.force_n.norm(), 0.0);
  CHECK(check_legal(part, upright_at(25.0, 12.5, kTop_mm + 0.5)) == Legality::Legal);
}

TEST(ContactQuery, PressingIntoTheTopPushesStraightUpWithKTimesTheDeviceDepth) {
  for (const double depth : {0.01, 0.05, 0.2}) {
    const ContactResult result = query_contacts(part, upright_at(25.3, 12.1, kTop_mm - depth), parameters);
    CHECK(result.status == QueryStatus::Ok);
    CHECK(result.penetrating_points > 0);
    check_depth(part, depth, result);
    // k = 1 N per device mm; the device moves 10 mm per world mm.
    DOUBLES_EQUAL(10.0 * result.max_depth_mm, result.force_n.norm(), 1e-9);
    CHECK(result.force_n.normalized().dot(Eigen::Vector3d::UnitZ()) > 0.999);
    CHECK(check_legal(part, upright_at(25.3, 12.1, kTop_mm - depth)) == Legality::Illegal);
  }
}

TEST(ContactQuery, StiffnessDoesNotGrowWithTheNumberOfPointsInContact) {
  // A deeper press brings many more points into contact; the force still follows depth alone.
  const ContactResult shallow = query_contacts(part, upright_at(25.3, 12.1, kTop_mm - 0.02), parameters);
  const ContactResult deep = query_contacts(part, upright_at(25.3, 12.1, kTop_mm - 0.4), parameters);
  CHECK(deep.penetrating_points > 4 * shallow.penetrating_points);
  DOUBLES_EQUAL(10.0 * shallow.max_depth_mm, shallow.force_n.norm(), 1e-9);
  DOUBLES_EQUAL(10.0 * deep.max_depth_mm, deep.force_n.norm(), 1e-9);
}

TEST(ContactQuery, PressingSidewaysIntoAFacePushesAlongItsNormal) {
  // The tool's side (radius 1.5) against the side face, 0.1 mm in, its tip at z = 2.
  const double depth = 0.1;
  const Eigen::Vector3d axis_at = Eigen::Vector3d(25.0, 12.5, 2.0) + (kApothem_mm + 1.5 - depth) * kSideNormal;
  const ContactResult result = query_contacts(part, upright_at(axis_at.x(), axis_at.y(), 2.0), parameters);
  CHECK(result.penetrating_points > 0);
  check_depth(part, depth, result);
  CHECK(result.force_n.normalized().dot(kSideNormal) > 0.999);
  // The contact is below the compliance centre (10 mm up the axis): the push at the bottom turns
  // the tool about the horizontal axis z x n, negatively.
  CHECK(result.torque_nmm.dot(Eigen::Vector3d::UnitZ().cross(kSideNormal)) < 0.0);
}

TEST(ContactQuery, TouchingIsLegalAndExactlyTheSameQueryGivesTheSameBits) {
  CHECK(check_legal(part, upright_at(25.3, 12.1, kTop_mm + 1e-6)) == Legality::Legal);
  const ContactResult a = query_contacts(part, upright_at(25.31, 12.17, kTop_mm - 0.13), parameters);
  const ContactResult b = query_contacts(part, upright_at(25.31, 12.17, kTop_mm - 0.13), parameters);
  CHECK(a.force_n == b.force_n);
  CHECK(a.torque_nmm == b.torque_nmm);
  LONGS_EQUAL(a.penetrating_points, b.penetrating_points);
}

TEST(ContactQuery, APoseThatIsNotANumberIsRefusedNotAnswered) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(query_contacts(part, upright_at(nan, 12.5, 3.0), parameters).status == QueryStatus::BadInput);
  CHECK(query_contacts(part, {{25.0, 12.5, 3.0}, {0.0, 0.0, 2.0}}, parameters).status == QueryStatus::BadInput);
  CHECK(check_legal(part, upright_at(25.0, nan, 3.0)) == Legality::Fault);
}

// Tables that did not come through the loader: a node whose right child is itself. Wherever the
// walk meets it, in the tree's mixed nodes or in a subtree settled in one region, it ends in a bad
// tree (the walk's budget of the node count runs out: its stack only cycles) rather than looping;
// where the walk never opens it, the answer is the sound tree's.
TEST(ContactQuery, ANodeThatIsItsOwnChildEndsTheWalkAsABadTreeWhereverTheWalkMeetsIt) {
  const ToolPose pose = upright_at(25.3, 12.1, kTop_mm - 0.2);
  const ContactResult sound = query_contacts(part, pose, parameters);
  CHECK(sound.status == QueryStatus::Ok && sound.penetrating_points > 0);
  std::vector<tables::BvhNode> nodes(part.nodes, part.nodes + part.node_count());
  tables::PartTables damaged = part;
  damaged.nodes = nodes.data();
  int bad = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].point_count > 0) {
      continue;
    }
    const std::uint32_t right = nodes[i].right_child;
    nodes[i].right_child = static_cast<std::uint32_t>(i);
    const ContactResult result = query_contacts(damaged, pose, parameters);
    const Legality legality = check_legal(damaged, pose);
    nodes[i].right_child = right;
    if (result.status == QueryStatus::BadTree) {
      ++bad;
      LONGS_EQUAL(0, result.penetrating_points);
      CHECK(legality == Legality::Fault || legality == Legality::Illegal);  // it may stop at a penetrating leaf first
    } else {
      CHECK(result.status == QueryStatus::Ok);
      CHECK(result.force_n == sound.force_n);
      CHECK(result.torque_nmm == sound.torque_nmm);
      LONGS_EQUAL(sound.penetrating_points, result.penetrating_points);
      DOUBLES_EQUAL(sound.max_depth_mm, result.max_depth_mm, 0.0);
      LONGS_EQUAL(sound.deepest_point, result.deepest_point);
    }
  }
  // The root, the nodes down to the contact, and the settled subtrees' nodes walked into.
  CHECK(bad > 5);
}

// Legality is the query's answer: illegal exactly where a point penetrates, and never a fault on
// sound tables, however deep the plunge. A wide flat end deep in the dense part's tree meets mixed
// nodes wholly deep in one region, whose leaves the walk takes as a run: legality stops at the
// first of them (an illegal pose, not a bad tree).
TEST(ContactQuery, LegalityIsIllegalExactlyWhereThePlungePenetratesNeverAFault) {
  const tablegen::TableBytes dense_bytes = table_at_spacing("flat:d=8", 0.04);
  tables::PartTables dense{};
  CHECK(tables::load_tables({dense_bytes.data(), dense_bytes.size()}, dense).ok);
  int illegal = 0;
  for (const double x : {17.0, 19.2, 23.0, 25.0, 28.5, 31.0}) {
    for (const double y : {9.0, 12.5, 14.3, 16.0}) {
      for (const double z : {kTop_mm + 0.001, kTop_mm - 0.3, 2.0, -1.31}) {
        const ToolPose pose = upright_at(x, y, z);
        const ContactResult result = query_contacts(dense, pose, parameters);
        CHECK(result.status == QueryStatus::Ok);
        const Legality legality = check_legal(dense, pose);
        CHECK(legality == (result.penetrating_points > 0 ? Legality::Illegal : Legality::Legal));
        illegal += legality == Legality::Illegal ? 1 : 0;
      }
    }
  }
  CHECK(illegal > 40);
}

TEST(ContactQuery, TouchedTrianglesAreThoseNearTheToolOnly) {
  geometry::ToolBsp contact_tool{};
  CHECK(build_contact_tool(part.tool.spec, 0.01, contact_tool));
  TriangleSet touched;
  // Resting on the top face: only top facets can be touched.
  CHECK(mark_touched(part, contact_tool, upright_at(25.3, 12.1, kTop_mm + 0.001), 0.01, touched) > 0);
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    if (touched.contains(t)) {
      const auto& v = part.triangles[t].vertices;
      CHECK(v[0].z_mm == 6.0f && v[1].z_mm == 6.0f && v[2].z_mm == 6.0f);
    }
  }
  // Hovering 0.05 mm above: nothing.
  TriangleSet none;
  LONGS_EQUAL(0, mark_touched(part, contact_tool, upright_at(25.3, 12.1, kTop_mm + 0.05), 0.01, none));
}

TEST_GROUP(ContactForceContinuity){};

TEST(ContactForceContinuity, ForceChangesSmoothlyAsContactCrossesTheToolsRegions) {
  // A bull-nose end mill (flat bottom, corner torus, side) 0.1 mm into the top of the prism, moved
  // off its edge in fine steps: contact passes from the bottom to the corner to the side of the tool.
  tablegen::GeneratorOptions options = test::default_job_options(2);
  options.tool = tablegen::parse_tool("bull:d=6,r=1", "");
  const tablegen::TableBytes bytes = test::make_table(test::default_part(), options);
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  const ContactParameters parameters{};
  const double step = 0.002;  // mm
  Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
  double largest_jump = 0.0;
  int in_contact = 0;
  // Along -x from over the face to past the corner at x = 17 (the prism's -x corner), y through the centre.
  for (double x = 22.0; x > 13.0; x -= step) {
    const ContactResult result = query_contacts(part, {{x, 12.5, 6.0 - 0.1}, Eigen::Vector3d::UnitZ()}, parameters);
    if (result.penetrating_points > 0) {
      ++in_contact;
    }
    if (x < 22.0) {
      largest_jump = std::max(largest_jump, (result.force_n - previous_force).norm());
    }
    previous_force = result.force_n;
  }
  CHECK(in_contact > 1000);
  // k_world = 10 N/mm: a 2 um step may change the force by a fraction of 10 * 0.1 = 1 N, never jump by it.
  CHECK_TEXT(largest_jump < 0.1, "the contact force jumped");
}

TEST_GROUP(ContactQueryOracle){};

// The query settles whole leaves at once (the leaf's box against the tool tree, the points' numbers
// lane by lane, and a leaf wholly deeper than the tolerance from its moments alone); here every
// point goes through classify_at_pose on its own, in a plain loop, and the results must agree:
// count, deepest point and depth exactly, legality, touched triangles; force and torque to the
// float lanes' rounding where no leaf lies wholly in the part (no leaf can be settled from its
// moments), and otherwise to what the moments leave out: the force's direction within half a
// degree, its torque per newton within 0.05 mm.
TEST(ContactQueryOracle, LeafByLeafAgreesWithEveryPointThroughTheToolTree) {
  std::mt19937_64 random(404);
  for (const char* tool_text : {"ball:d=3", "flat:d=3", "bull:d=4,r=1"}) {
    const tablegen::TableBytes bytes = table_at_spacing(tool_text, 0.08);
    tables::PartTables part{};
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    const ContactParameters parameters{};
    const double k_world = 10.0;
    constexpr double kTolerance = 0.002;
    geometry::ToolBsp contact_tool{};
    CHECK(build_contact_tool(part.tool.spec, kTolerance, contact_tool));
    int poses_in_contact = 0;
    int poses_exact = 0;
    int poses_from_moments = 0;
    double worst_angle = 0.0;
    double worst_lever = 0.0;
    for (int trial = 0; trial < 300; ++trial) {
      // Tips near the top face, the side faces and the prism's edges, up to 0.6 mm into the part,
      // and low beside the side faces so that the tool's partition planes (a ball's equator, a
      // bull-nose's corner top) cross the faces.
      const Eigen::Vector3d tip = tip_near_the_faces(random, trial, 1.6, kTop_mm - 0.3, 0.9);
      const ToolPose pose = upright_at(tip.x(), tip.y(), tip.z());
      std::uint32_t count = 0;
      double deepest = 0.0;
      Eigen::Vector3d force = Eigen::Vector3d::Zero();
      Eigen::Vector3d torque = Eigen::Vector3d::Zero();
      double force_terms = 0.0;   // how far the float lanes' rounding may move the force sum
      double torque_terms = 0.0;  // and the torque sum
      const Eigen::Vector3d centre = tip + parameters.compliance_centre_mm * Eigen::Vector3d::UnitZ();
      TriangleSet expected_touched;
      const Eigen::Vector3d inflated_tip = tip - kTolerance * Eigen::Vector3d::UnitZ();
      std::vector<bool> penetrates(part.point_count(), false);
      for (std::uint32_t i = 0; i < part.point_count(); ++i) {
        const Eigen::Vector3d p(part.points[i].x_mm, part.points[i].y_mm, part.points[i].z_mm);
        const tables::PackedPoint normal = tables::point_normal(part, i);
        const Eigen::Vector3d n(normal.x_mm, normal.y_mm, normal.z_mm);
        if (geometry::classify_at_pose(contact_tool, inflated_tip, Eigen::Vector3d::UnitZ(), p).contact !=
            geometry::PointContact::Outside) {
          expected_touched.insert(part.triangle_ids[i]);
        }
        const auto c = geometry::classify_at_pose(part.tool, tip, Eigen::Vector3d::UnitZ(), p);
        if (c.contact != geometry::PointContact::Penetrating) {
          continue;
        }
        penetrates[i] = true;
        ++count;
        deepest = std::max(deepest, c.depth_mm);
        const Eigen::Vector3d direction = n - c.escape_direction;
        if (direction.norm() >= 1e-12) {
          const Eigen::Vector3d f = k_world * c.depth_mm * direction.normalized();
          force += f;
          torque += (p - centre).cross(f);
          // A few float roundings per term: of the depth, a difference of millimetre-sized numbers
          // (so absolute, about 1e-7 mm per mm of offset), and of the direction normalize(v_i),
          // relative to |f_i| / |v_i| where the normal and escape nearly cancel (at most 2 |f_i|).
          const double term = k_world * 1e-6 * ((p - tip).norm() + 4.0) +
                              f.norm() * std::min(2.0, 1e-6 * (1.0 + 2.0 / direction.norm()));
          force_terms += term;
          torque_terms += (p - centre).norm() * term;
        }
      }
      const ContactResult result = query_contacts(part, pose, parameters);
      CHECK(result.status == QueryStatus::Ok);
      LONGS_EQUAL(count, result.penetrating_points);
      DOUBLES_EQUAL(deepest, result.max_depth_mm, 1e-12);
      const double scale = force.norm() > 0.0 ? k_world * deepest / force.norm() : 0.0;
      bool a_leaf_wholly_in = false;
      for (std::uint32_t leaf = 0; leaf < part.leaf_count(); ++leaf) {
        const tables::LeafBlock& block = part.leaves[leaf];
        bool all = true;
        for (std::uint32_t i = block.first_point; i < block.first_point + block.point_count; ++i) {
          all = all && penetrates[i];
        }
        a_leaf_wholly_in = a_leaf_wholly_in || all;
      }
      if (!a_leaf_wholly_in) {
        // The lanes compute each point's force and torque in single precision (24-bit), so the sums
        // agree to the terms' rounding bound above (torques about the compliance centre 10 mm up
        // cancel to far less than their terms, so the bound is on the terms, not on the sum).
        CHECK((result.force_n - scale * force).norm() <= 1e-9 + scale * force_terms);
        CHECK((result.torque_nmm - scale * torque).norm() <= 1e-9 + scale * torque_terms);
        ++poses_exact;
      } else if (count > 0) {
        // The same magnitude (k times the deepest depth), its direction and the torque per newton
        // as near as the leaves' moments give them.
        DOUBLES_EQUAL(k_world * deepest, result.force_n.norm(), 1e-9);
        const double turned = std::acos(std::min(1.0, result.force_n.normalized().dot(force.normalized())));
        const double lever = (result.torque_nmm - scale * torque).norm() / (k_world * deepest);
        worst_angle = std::max(worst_angle, turned);
        worst_lever = std::max(worst_lever, lever);
        ++poses_from_moments;
      }
      if (count > 0) {
        const ContactResult again = query_contacts(part, pose, parameters);  // the same bits
        CHECK(again.max_depth_mm == result.max_depth_mm && again.deepest_point == result.deepest_point &&
              again.penetrating_points == result.penetrating_points && again.force_n == result.force_n &&
              again.torque_nmm == result.torque_nmm);
        const auto& p = part.points[result.deepest_point];
        const auto d = geometry::classify_at_pose(part.tool, tip, Eigen::Vector3d::UnitZ(), {p.x_mm, p.y_mm, p.z_mm});
        DOUBLES_EQUAL(deepest, d.depth_mm, 1e-12);
        ++poses_in_contact;
      }
      CHECK((check_legal(part, pose) == Legality::Legal) == (count == 0));
      TriangleSet touched;
      static_cast<void>(mark_touched(part, contact_tool, pose, kTolerance, touched));
      LONGS_EQUAL(expected_touched.count(), touched.count());
      for (std::uint32_t id = 0; id < part.triangle_count(); ++id) {
        CHECK(touched.contains(id) == expected_touched.contains(id));
      }
    }
    CHECK_TEXT(poses_in_contact > 60, tool_text);
    // Measured with this seed: at most 0.095 degrees and 0.015 mm (the flat end), 0 for poses
    // where no leaf could be settled whole.
    CHECK_TEXT(poses_exact > 50 && poses_from_moments > 50, tool_text);
    CHECK_TEXT(worst_angle < 0.5 / 57.29577951308232, tool_text);
    CHECK_TEXT(worst_lever < 0.05, tool_text);
  }
}

// A flat end 0.3 mm into the top face: every point under its bottom is exactly as deep as every
// other, many whole leaves lie deeper than the tolerance (settled from their moments, their deepest
// point searched after the walk), and the deepest point is still the walk's own answer, the first
// of them in the points' order. Under a plane, with one normal, the moments give the points' own
// force and torque: to the float lanes' rounding.
TEST(ContactQueryOracle, AFlatBottomDeepInAFaceGivesTheFirstOfEquallyDeepPointsAndTheirOwnForce) {
  const tablegen::TableBytes bytes = table_at_spacing("flat:d=3", 0.04);
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  const ContactParameters parameters{};
  const double k_world = 10.0;
  const Eigen::Vector3d tip(25.3, 12.1, kTop_mm - 0.3);
  const Eigen::Vector3d centre = tip + parameters.compliance_centre_mm * Eigen::Vector3d::UnitZ();
  std::uint32_t count = 0;
  std::uint32_t first_deepest = 0;
  double deepest = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const Eigen::Vector3d p(part.points[i].x_mm, part.points[i].y_mm, part.points[i].z_mm);
    const auto c = geometry::classify_at_pose(part.tool, tip, Eigen::Vector3d::UnitZ(), p);
    if (c.contact != geometry::PointContact::Penetrating) {
      continue;
    }
    ++count;
    if (c.depth_mm > deepest) {
      deepest = c.depth_mm;
      first_deepest = i;
    }
    const tables::PackedPoint normal = tables::point_normal(part, i);
    const Eigen::Vector3d f =
        k_world * c.depth_mm * (Eigen::Vector3d(normal.x_mm, normal.y_mm, normal.z_mm) - c.escape_direction).normalized();
    force += f;
    torque += (p - centre).cross(f);
  }
  const ContactResult result = query_contacts(part, upright_at(tip.x(), tip.y(), tip.z()), parameters);
  CHECK(count > 1000);
  LONGS_EQUAL(count, result.penetrating_points);
  DOUBLES_EQUAL(deepest, result.max_depth_mm, 0.0);
  LONGS_EQUAL(first_deepest, result.deepest_point);
  const double scale = k_world * deepest / force.norm();
  CHECK((result.force_n - scale * force).norm() < 1e-5 * result.force_n.norm());
  CHECK((result.torque_nmm - scale * torque).norm() < 1e-5 * (scale * torque).norm() + 1e-9);
}

// A ball end 0.5 mm into the top face: its deepest point lies under its centre, in a leaf wholly
// deeper than the tolerance and settled from its moments, so the query finds it only in the search
// after the walk; it is the point-by-point answer, and so are the count and the depth.
TEST(ContactQueryOracle, ABallDeepInAFaceFindsItsDeepestPointInALeafSettledFromItsMoments) {
  // Leaves small enough against the ball's curvature to be settled from their moments.
  const tablegen::TableBytes bytes = table_at_spacing("ball:d=3", 0.025);
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  const Eigen::Vector3d tip(25.3, 12.1, kTop_mm - 0.5);
  std::uint32_t count = 0;
  std::uint32_t first_deepest = 0;
  double deepest = 0.0;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const Eigen::Vector3d p(part.points[i].x_mm, part.points[i].y_mm, part.points[i].z_mm);
    const auto c = geometry::classify_at_pose(part.tool, tip, Eigen::Vector3d::UnitZ(), p);
    if (c.contact == geometry::PointContact::Penetrating) {
      ++count;
      first_deepest = c.depth_mm > deepest ? i : first_deepest;
      deepest = std::max(deepest, c.depth_mm);
    }
  }
  const ContactResult result = query_contacts(part, upright_at(tip.x(), tip.y(), tip.z()), ContactParameters{});
  CHECK(count > 1000);
  LONGS_EQUAL(count, result.penetrating_points);
  DOUBLES_EQUAL(deepest, result.max_depth_mm, 0.0);
  LONGS_EQUAL(first_deepest, result.deepest_point);
}

namespace {

// The walk's force and torque sums, without its walk: every leaf's box classified from the tool
// tree's root on its own, in the leaves' order (the walk's), each leaf's share computed as the
// walk computes it for that classification: from its moments where its box lies wholly deeper than
// the tolerance in one region and they settle it, else lane by lane (in one region, split at a
// plane, or point by point). What the walk settles for whole subtrees (walk_settled, walk_split,
// a wholly deep run) must give these bits exactly. `split` and `deep` count the leaves split at a
// plane and those settled from their moments.
struct LeafByLeaf {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  int split = 0;
  int deep = 0;
};
LeafByLeaf leaf_by_leaf_sums(const tables::PartTables& part, const Eigen::Vector3d& tip, const ContactParameters& parameters) {
  const double k_world = parameters.stiffness_n_per_device_mm * parameters.device_mm_per_world_mm;
  const double height = parameters.compliance_centre_mm;
  const Eigen::Vector3d centre = tip + height * Eigen::Vector3d::UnitZ();
  const LeafTip split_tip = leaf_tip(tip);
  LeafByLeaf sums;
  LeafContacts leaf;
  for (std::uint32_t index = 0; index < part.node_count(); ++index) {
    const tables::BvhNode& node = part.nodes[index];
    if (node.point_count == 0) {
      continue;
    }
    const tables::LeafBlock& block = part.leaves[node.leaf];
    const Eigen::Vector3d low(node.dop_min[0], node.dop_min[1], node.dop_min[2]);
    const Eigen::Vector3d high(node.dop_max[0], node.dop_max[1], node.dop_max[2]);
    const geometry::MeridianBox box = geometry::upright_meridian_box(tip, low, high);
    const geometry::BoxClassification cover = geometry::classify_meridian_box(part.tool, box);
    bind_leaf(part, block, split_tip, leaf);
    RegionLeafForce share{};
    switch (cover.cover) {
      case geometry::BoxCover::Outside:
        continue;
      case geometry::BoxCover::Region:
      case geometry::BoxCover::RegionOrOutside: {
        if (geometry::region_depth_range(part.tool, cover.region, box).shallowest_mm > geometry::kSurfaceTolerance_mm) {
          const geometry::ImplicitSurface& surface = part.tool.surfaces[part.tool.regions[cover.region].surface];
          const LeafMomentForce moment = leaf_moment_force(surface, block, tip, centre, k_world);
          if (moment.settled) {
            sums.force += moment.force;
            sums.torque += moment.torque;
            ++sums.deep;
            continue;
          }
        }
        CHECK(region_leaf_force(part.tool, cover.region, cover.cover == geometry::BoxCover::RegionOrOutside, false,
                                k_world, height, leaf, share));
        break;
      }
      case geometry::BoxCover::SplitAtZ:
        CHECK(split_leaf_force(part.tool, cover, false, k_world, height, leaf, share));
        ++sums.split;
        break;
      case geometry::BoxCover::Mixed:
        load_lanes(leaf);
        CHECK(mixed_leaf_contacts(part.tool, leaf));
        share.penetrating = leaf.penetrating;
        share.sums = leaf_forces(leaf, k_world, height);
        break;
    }
    if (share.penetrating > 0) {
      sums.force += share.sums.force;
      sums.torque += share.sums.torque;
    }
  }
  return sums;
}

}  // namespace

// The walk settles whole subtrees without the tool tree: below a node in one region by that
// region's depth alone, below a node across a partition plane (a ball's centre, a bull nose's
// corner top) by its two sides. Each of those is a shortcut to what classifying every leaf's box
// from the tool tree's root gives, so the force and torque must be those bits exactly, not merely
// as near as the lanes' rounding: the tips below put the planes across the faces and the tools
// deep into them.
TEST(ContactQueryOracle, SubtreesSettledWholeGiveTheBitsOfEveryLeafClassifiedOnItsOwn) {
  const ContactParameters parameters{};
  const double k_world = parameters.stiffness_n_per_device_mm * parameters.device_mm_per_world_mm;
  std::mt19937_64 random(909);
  for (const char* tool_text : {"ball:d=3", "bull:d=4,r=1", "flat:d=3"}) {
    int in_contact = 0;
    const tablegen::TableBytes bytes = table_at_spacing(tool_text, 0.05);
    tables::PartTables part{};
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    int with_split_leaves = 0;
    int with_deep_leaves = 0;
    for (int trial = 0; trial < 120; ++trial) {
      const Eigen::Vector3d tip = tip_near_the_faces(random, trial, 1.2, kTop_mm - 0.4, 0.5);
      const ContactResult result = query_contacts(part, upright_at(tip.x(), tip.y(), tip.z()), parameters);
      CHECK(result.status == QueryStatus::Ok);
      const LeafByLeaf expected = leaf_by_leaf_sums(part, tip, parameters);
      const double magnitude = expected.force.norm();
      const double scale = magnitude > 0.0 ? k_world * result.max_depth_mm / magnitude : 0.0;
      const Eigen::Vector3d force = magnitude > 0.0 ? Eigen::Vector3d(scale * expected.force) : Eigen::Vector3d::Zero();
      const Eigen::Vector3d torque = magnitude > 0.0 ? Eigen::Vector3d(scale * expected.torque) : Eigen::Vector3d::Zero();
      CHECK_TEXT(result.force_n == force && result.torque_nmm == torque, tool_text);
      in_contact += result.penetrating_points > 0 ? 1 : 0;
      with_split_leaves += result.penetrating_points > 0 && expected.split > 0 ? 1 : 0;
      with_deep_leaves += expected.deep > 0 ? 1 : 0;
    }
    CHECK_TEXT(in_contact > 40, tool_text);
    // Not idle: planes across the contact (no flat end has one) and leaves settled whole.
    CHECK_TEXT(std::string(tool_text).rfind("flat", 0) == 0 || with_split_leaves > 10, tool_text);
    CHECK_TEXT(with_deep_leaves > 10, tool_text);
  }
}
