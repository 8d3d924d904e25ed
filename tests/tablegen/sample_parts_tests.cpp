// The project's sample parts (toolchain/tablegen/sample_parts): each a closed solid with its facets
// counter-clockwise seen from outside (a positive volume by the divergence theorem, every edge shared
// by exactly two facets in opposite directions), of the size asked; the STL bytes of either kind.
// That the committed sample files match: e2e sample_parts_match_the_committed_files.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;

namespace {

double signed_volume(const std::vector<Facet>& facets) {
  double volume = 0.0;
  for (const Facet& f : facets) {
    volume += f[0].dot(f[1].cross(f[2])) / 6.0;
  }
  return volume;
}

// Every directed edge used once and its reverse once: closed and consistently oriented.
bool closed_and_oriented(const std::vector<Facet>& facets) {
  using Key = std::array<double, 6>;
  std::map<Key, int> directed;
  for (const Facet& f : facets) {
    for (std::size_t i = 0; i < 3; ++i) {
      const Eigen::Vector3d& a = f[i];
      const Eigen::Vector3d& b = f[(i + 1) % 3];
      ++directed[{a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}];
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge[3], edge[4], edge[5], edge[0], edge[1], edge[2]});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) {
      return false;
    }
  }
  return true;
}

Eigen::Vector3d low_corner(const std::vector<Facet>& facets) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300);
  for (const Facet& f : facets) {
    for (const Eigen::Vector3d& v : f) {
      low = low.cwiseMin(v);
    }
  }
  return low;
}

Eigen::Vector3d high_corner(const std::vector<Facet>& facets) {
  Eigen::Vector3d high = Eigen::Vector3d::Constant(-1e300);
  for (const Facet& f : facets) {
    for (const Eigen::Vector3d& v : f) {
      high = high.cwiseMax(v);
    }
  }
  return high;
}

}  // namespace

TEST_GROUP(SampleParts){};

TEST(SampleParts, TheHexagonalPrismIsAClosedOutwardSolidOfItsSize) {
  const std::vector<Facet> prism = hexagonal_prism(8.0, 6.0, 25.0, 12.5);
  CHECK_TRUE(closed_and_oriented(prism));
  // A regular hexagon of circumradius R has area 3 sqrt(3) / 2 R^2.
  DOUBLES_EQUAL(3.0 * std::sqrt(3.0) / 2.0 * 64.0 * 6.0, signed_volume(prism), 1e-9);
  DOUBLES_EQUAL(0.0, low_corner(prism).z(), 0.0);
  DOUBLES_EQUAL(6.0, high_corner(prism).z(), 1e-12);
}

TEST(SampleParts, TheSlottedBlockIsTheBlockLessItsSlot) {
  const std::vector<Facet> block = slotted_block(30.0, 16.0, 8.0, 2.0, 4.0, 10.0, 5.0);
  CHECK_TRUE(closed_and_oriented(block));
  DOUBLES_EQUAL(30.0 * 16.0 * 8.0 - 30.0 * 2.0 * 4.0, signed_volume(block), 1e-9);
  DOUBLES_EQUAL(10.0, low_corner(block).x(), 1e-12);
  DOUBLES_EQUAL(21.0, high_corner(block).y(), 1e-12);
}

TEST(SampleParts, TheThinFinIsAClosedPlate) {
  const std::vector<Facet> fin = thin_fin(20.0, 0.8, 10.0, 15.0, 12.0);
  CHECK_TRUE(closed_and_oriented(fin));
  DOUBLES_EQUAL(20.0 * 0.8 * 10.0, signed_volume(fin), 1e-9);
}

TEST(SampleParts, TheDomeHasAboutTheFacetsAskedAndRisesAboveItsBase) {
  const std::vector<Facet> dome = tessellated_dome(20000, 5.0, 5.0, 40.0, 15.0, 2.0, 3.0);
  CHECK(dome.size() > 15000U && dome.size() < 25000U);
  DOUBLES_EQUAL(5.0, low_corner(dome).x(), 1e-9);
  DOUBLES_EQUAL(45.0, high_corner(dome).x(), 1e-9);
  CHECK(high_corner(dome).z() > 2.0 + 2.5);
  CHECK(high_corner(dome).z() <= 2.0 + 1.2 * 3.0 + 1e-9);  // the bump is rippled by up to a fifth
}

TEST(SampleParts, BinaryStlIsAHeaderACountAnd50BytesAFacet) {
  const std::vector<Facet> prism = hexagonal_prism(8.0, 6.0, 25.0, 12.5);
  const std::vector<std::byte> bytes = encode_stl(prism, true, "hex");
  CHECK_EQUAL(84U + 50U * prism.size(), bytes.size());
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, sizeof count);
  CHECK_EQUAL(prism.size(), count);
  const std::string header(reinterpret_cast<const char*>(bytes.data()));
  STRCMP_EQUAL("binary STL written by stencil-sample-parts: hex", header.c_str());
  // The first facet's first vertex, as floats after its normal.
  float x = 0.0f;
  std::memcpy(&x, bytes.data() + 84 + 12, sizeof x);
  DOUBLES_EQUAL(prism[0][0].x(), x, 1e-5);
}

TEST(SampleParts, AsciiStlIsOneSolidOfNamedFacets) {
  const std::vector<Facet> fin = thin_fin(20.0, 0.8, 10.0, 15.0, 12.0);
  const std::vector<std::byte> bytes = encode_stl(fin, false, "fin");
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  CHECK_EQUAL(0U, text.find("solid fin\n"));
  std::size_t facets = 0;
  for (std::size_t at = text.find("facet normal"); at != std::string::npos; at = text.find("facet normal", at + 1)) {
    ++facets;
  }
  CHECK_EQUAL(fin.size(), facets);
  STRCMP_CONTAINS("endsolid fin", text.c_str());
}

TEST(SampleParts, WritingWhereNothingCanBeWrittenNamesThePath) {
  try {
    write_stl("/nonexistent-folder/part.stl", thin_fin(20.0, 0.8, 10.0, 15.0, 12.0), true, "fin");
    FAIL("no InputError");
  } catch (const InputError& error) {
    STRCMP_CONTAINS("/nonexistent-folder/part.stl: cannot write (", error.what());
  }
}
