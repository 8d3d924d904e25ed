// Lane-wise depth, escape direction and force for the points of one leaf (upright tool), in
// single precision, with every verdict checked in double precision where the lanes cannot tell.
#include "firmware/core/stencil/leaf_contacts.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stencil::engine {
namespace {

using geometry::SurfaceKind;
constexpr std::uint32_t kLanes = tables::kMaxLeafPoints;

// As in classify_at_pose: below this radius a point's radial direction is meaningless, and below
// this distance from a sphere's or torus's centre its gradient is.
constexpr float kOnAxisRadius_mm = 1e-12F;
constexpr float kDegenerateDistance_mm = 1e-12F;
constexpr float kInvSqrt2 = 0.70710678F;
constexpr float kTolerance_mm = static_cast<float>(geometry::kSurfaceTolerance_mm);

// The loops below are plain loops over the leaf's lanes, which the compiler vectorises (selects
// become blends); sums and maxima are taken in a fixed order of eight partial lanes, since the
// compiler may not reorder a floating-point reduction itself. The same binary gives the same bits.
// region_leaf_force's fused pass does the same operations in AVX2 registers, in the same order.
constexpr std::uint32_t kPartials = 8;

float lane_sum(const LeafLanes& a) {
#if defined(__AVX2__)
  // The same additions in the same order as the loop below, eight partials to a register.
  __m256 partial = _mm256_setzero_ps();
  for (std::uint32_t base = 0; base < kLanes; base += kPartials) {
    partial = _mm256_add_ps(partial, _mm256_loadu_ps(a.data() + base));
  }
  const __m128 q = _mm_add_ps(_mm256_castps256_ps128(partial), _mm256_extractf128_ps(partial, 1));  // p0+p4 .. p3+p7
  const __m128 r = _mm_add_ps(q, _mm_movehl_ps(q, q));  // (p0+p4)+(p2+p6), (p1+p5)+(p3+p7)
  return _mm_cvtss_f32(_mm_add_ss(r, _mm_shuffle_ps(r, r, 1)));
#else
  std::array<float, kPartials> partial{};
  for (std::uint32_t base = 0; base < kLanes; base += kPartials) {
    for (std::uint32_t j = 0; j < kPartials; ++j) {
      partial[j] += a[base + j];
    }
  }
  return ((partial[0] + partial[4]) + (partial[2] + partial[6])) + ((partial[1] + partial[5]) + (partial[3] + partial[7]));
#endif
}

// The largest lane. The lanes it is given are finite (offsets and depths of finite points), and a
// maximum is exact, so the order of the comparisons cannot change it.
float lane_max(const LeafLanes& a) {
#if defined(__AVX2__)
  __m256 m = _mm256_loadu_ps(a.data());
  for (std::uint32_t base = 8; base < kLanes; base += 8) {
    m = _mm256_max_ps(m, _mm256_loadu_ps(a.data() + base));
  }
  const __m128 q = _mm_max_ps(_mm256_castps256_ps128(m), _mm256_extractf128_ps(m, 1));
  const __m128 r = _mm_max_ps(q, _mm_movehl_ps(q, q));
  return _mm_cvtss_f32(_mm_max_ss(r, _mm_shuffle_ps(r, r, 1)));
#else
  std::array<float, kPartials> partial{};
  for (std::uint32_t j = 0; j < kPartials; ++j) {
    partial[j] = a[j];
  }
  for (std::uint32_t base = kPartials; base < kLanes; base += kPartials) {
    for (std::uint32_t j = 0; j < kPartials; ++j) {
      partial[j] = std::max(partial[j], a[base + j]);
    }
  }
  float best = partial[0];
  for (std::uint32_t j = 1; j < kPartials; ++j) {
    best = std::max(best, partial[j]);
  }
  return best;
#endif
}

// Per-lane verdicts, -1 where true: what the vectorised compares write, packed into a LaneMask.
using LaneFlags = std::array<std::int32_t, kLanes>;

LaneMask pack(const LaneFlags& flags) {
#if defined(__AVX2__)
  LaneMask mask = 0;
  for (std::uint32_t base = 0; base < kLanes; base += 8) {
    const __m256 block = _mm256_castsi256_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(flags.data() + base)));
    mask |= static_cast<LaneMask>(_mm256_movemask_ps(block)) << base;
  }
  return mask;
#else
  LaneMask mask = 0;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    mask |= flags[lane] != 0 ? LaneMask{1} << lane : 0U;
  }
  return mask;
#endif
}

#if defined(__AVX2__)
// Lanes base..base+7 of the leaf's offsets from the tip, from its block: (p - high) - low, the
// tip's parts splatted once per leaf.
struct PointLanes {
  __m256 x, y, z;
};
struct TipLanes {
  __m256 high_x, high_y, high_z, low_x, low_y, low_z;
};
[[gnu::always_inline]] inline TipLanes tip_lanes(const LeafContacts& leaf) {
  return {_mm256_set1_ps(leaf.tip_high[0]), _mm256_set1_ps(leaf.tip_high[1]), _mm256_set1_ps(leaf.tip_high[2]),
          _mm256_set1_ps(leaf.tip_low[0]),  _mm256_set1_ps(leaf.tip_low[1]),  _mm256_set1_ps(leaf.tip_low[2])};
}
[[gnu::always_inline]] inline PointLanes point_lanes(const LeafContacts& leaf, const TipLanes& tip, std::uint32_t base) {
  const tables::LeafBlock& block = *leaf.normals;
  return {_mm256_sub_ps(_mm256_sub_ps(_mm256_loadu_ps(block.x_mm + base), tip.high_x), tip.low_x),
          _mm256_sub_ps(_mm256_sub_ps(_mm256_loadu_ps(block.y_mm + base), tip.high_y), tip.low_y),
          _mm256_sub_ps(_mm256_sub_ps(_mm256_loadu_ps(block.z_mm + base), tip.high_z), tip.low_z)};
}
#endif

LaneMask lanes_below(std::uint32_t count) { return count >= kLanes ? ~LaneMask{0} : (LaneMask{1} << count) - 1U; }

// How many points group `group` of the block has (0 past its points).
std::uint32_t group_count(const tables::LeafBlock& block, std::uint32_t group) {
  const std::uint32_t count = std::min(block.point_count, tables::kMaxLeafPoints);
  const std::uint32_t first = group * tables::kLeafGroupPoints;
  return first < count ? std::min(tables::kLeafGroupPoints, count - first) : 0U;
}


// Calls visit(lane) for each lane of the mask, lowest first.
template <typename Visit>
void for_each_lane(LaneMask mask, Visit&& visit) {
  while (mask != 0) {
    visit(static_cast<std::uint32_t>(std::countr_zero(mask)));
    mask &= mask - 1U;
  }
}

// The largest error of a float depth against the double one, for a leaf of this size and a
// surface with these numbers: each of the few roundings on the way (the offset, squares, sums, a
// square root or two, the difference with the radius) is at most half a float ulp of a quantity no
// larger than `scale`; 2^-19 of it is 32 half-ulps, several times what the longest chain (a torus)
// can reach.
float band_for(const LeafContacts& leaf, const geometry::ImplicitSurface& surface) {
  const double scale = static_cast<double>(leaf.magnitude_mm) + std::abs(surface.center_z_mm) +
                       std::abs(surface.center_r_mm) + std::abs(surface.radius_mm);
  return static_cast<float>(0x1p-19 * scale + 2.0 * geometry::kSurfaceTolerance_mm);
}

// The double-precision offset of a lane's point from the tip, as classify_at_pose computes it.
struct ExactOffset {
  double x, y, z;
};
ExactOffset exact_offset(const LeafContacts& leaf, std::uint32_t lane) {
  const tables::PackedPoint& p = leaf.points[lane];
  return {double{p.x_mm} - leaf.tip_mm.x(), double{p.y_mm} - leaf.tip_mm.y(), double{p.z_mm} - leaf.tip_mm.z()};
}

// The lane's interior distance to the surface in double precision: classify_meridian's number for
// a point in the surface's region.
double exact_depth(const LeafContacts& leaf, std::uint32_t lane, const geometry::ImplicitSurface& surface) {
  const ExactOffset o = exact_offset(leaf, lane);
  return geometry::interior_distance(surface, {std::sqrt(o.x * o.x + o.y * o.y), o.z});
}

// The meridian escape direction (radial, axial) turned into the world: radial along (x, y) / r,
// or along +y on the axis (classify_at_pose's fixed perpendicular to +z).
void escape_to_world(const LeafLanes& r, const LeafLanes& radial, const LeafLanes& axial, LeafContacts& leaf) {
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    const bool on_axis = !(r[lane] > kOnAxisRadius_mm);
    const float inverse = 1.0F / std::max(r[lane], kOnAxisRadius_mm);
    leaf.ex[lane] = on_axis ? 0.0F : radial[lane] * (leaf.x[lane] * inverse);
    leaf.ey[lane] = on_axis ? radial[lane] : radial[lane] * (leaf.y[lane] * inverse);
    leaf.ez[lane] = axial[lane];
  }
}

void radii_of(const LeafContacts& leaf, LeafLanes& r) {
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    r[lane] = std::sqrt(leaf.x[lane] * leaf.x[lane] + leaf.y[lane] * leaf.y[lane]);
  }
}

// Depth, escape and in_tool of every lane from one region's surface; a lane whose float depth is
// within the band of the surface is settled in double precision. Returns false on a non-finite
// result. The lanes past count are left to summarise().
bool surface_contacts(const geometry::ImplicitSurface& surface, bool or_outside, LeafContacts& leaf) {
  const float sign = surface.solid_side == geometry::SolidSide::Below ? 1.0F : -1.0F;
  const auto centre_z = static_cast<float>(surface.center_z_mm);
  const auto centre_r = static_cast<float>(surface.center_r_mm);
  const auto radius = static_cast<float>(surface.radius_mm);
  LeafLanes f;  // the surface's natural function
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        f[lane] = leaf.z[lane] - centre_z;
        leaf.ex[lane] = 0.0F;
        leaf.ey[lane] = 0.0F;
        leaf.ez[lane] = sign;
      }
      break;
    case SurfaceKind::Cylinder: {
      LeafLanes r, radial, axial;
      radii_of(leaf, r);
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        f[lane] = r[lane] - radius;
        radial[lane] = sign;
        axial[lane] = 0.0F;
      }
      escape_to_world(r, radial, axial, leaf);
      break;
    }
    case SurfaceKind::Sphere:
      // Centred on the axis: the meridian gradient (r, dz) / length is the 3-D one (x, y, dz) / length.
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        const float dz = leaf.z[lane] - centre_z;
        const float length = std::sqrt(leaf.x[lane] * leaf.x[lane] + leaf.y[lane] * leaf.y[lane] + dz * dz);
        f[lane] = length - radius;
        // At the centre: classify_at_pose's (1, -1) / sqrt(2) in the meridian, radial along +y.
        const bool degenerate = !(length >= kDegenerateDistance_mm);
        const float inverse = sign / std::max(length, kDegenerateDistance_mm);
        leaf.ex[lane] = degenerate ? 0.0F : leaf.x[lane] * inverse;
        leaf.ey[lane] = degenerate ? kInvSqrt2 : leaf.y[lane] * inverse;
        leaf.ez[lane] = degenerate ? -kInvSqrt2 : dz * inverse;
      }
      break;
    case SurfaceKind::Torus: {
      LeafLanes r, radial, axial;
      radii_of(leaf, r);
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        const float dr = r[lane] - centre_r;
        const float dz = leaf.z[lane] - centre_z;
        const float length = std::sqrt(dr * dr + dz * dz);
        f[lane] = length - radius;
        const bool degenerate = !(length >= kDegenerateDistance_mm);
        const float inverse = sign / std::max(length, kDegenerateDistance_mm);
        radial[lane] = degenerate ? kInvSqrt2 : dr * inverse;
        axial[lane] = degenerate ? -kInvSqrt2 : dz * inverse;
      }
      escape_to_world(r, radial, axial, leaf);
      break;
    }
    default:
      return false;
  }
  const float band = band_for(leaf, surface);
  LaneFlags penetrating, in_tool, uncertain;
  LeafLanes check;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    const float depth = -sign * f[lane];  // the interior distance to the region's surface
    leaf.depth[lane] = depth > kTolerance_mm ? depth : 0.0F;
    penetrating[lane] = depth > kTolerance_mm ? -1 : 0;
    // Straddling the region's boundary, a point is in the tool exactly when the boundary test that
    // leads to the region passes: -tolerance <= that same interior distance.
    in_tool[lane] = !or_outside || depth >= -kTolerance_mm ? -1 : 0;
    uncertain[lane] = std::abs(depth) <= band ? -1 : 0;
    check[lane] = f[lane] + leaf.ex[lane] + leaf.ey[lane] + leaf.ez[lane];
  }
  // An infinity or NaN anywhere makes the sum non-finite (inf - inf is NaN).
  if (!std::isfinite(lane_sum(check))) {
    return false;
  }
  const LaneMask valid = lanes_below(leaf.count);
  leaf.penetrating_lanes = pack(penetrating) & valid;
  leaf.in_tool = pack(in_tool) & valid;
  for_each_lane(pack(uncertain) & valid, [&](std::uint32_t lane) {
    const double depth = exact_depth(leaf, lane, surface);
    const LaneMask bit = LaneMask{1} << lane;
    const bool deeper = depth > geometry::kSurfaceTolerance_mm;
    leaf.depth[lane] = deeper ? static_cast<float>(depth) : 0.0F;
    leaf.penetrating_lanes = deeper ? leaf.penetrating_lanes | bit : leaf.penetrating_lanes & ~bit;
    leaf.in_tool = (!or_outside || depth >= -geometry::kSurfaceTolerance_mm) ? leaf.in_tool | bit : leaf.in_tool & ~bit;
  });
  return true;
}

void clear_contacts(LeafContacts& leaf) {
  leaf.depth.fill(0.0F);
  leaf.ex.fill(0.0F);
  leaf.ey.fill(0.0F);
  leaf.ez.fill(0.0F);
  leaf.in_tool = 0;
  leaf.penetrating_lanes = 0;
}

// Zeroes the depth past count (so sums may run over every lane), counts the penetrating lanes and
// finds the deepest in double precision: every penetrating lane whose float depth is within twice
// the band of the float maximum may be it. exact(lane) gives a lane's double-precision depth.
template <typename ExactDepth>
void summarise(float band, ExactDepth&& exact, LeafContacts& leaf) {
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    leaf.depth[lane] = lane < leaf.count ? leaf.depth[lane] : 0.0F;
  }
  leaf.penetrating = static_cast<std::uint32_t>(std::popcount(leaf.penetrating_lanes));
  leaf.max_depth_mm = 0.0;
  leaf.deepest_lane = 0;
  if (leaf.penetrating == 0) {
    return;
  }
  const float floor = lane_max(leaf.depth) - 2.0F * band;
  LaneFlags near_deepest;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    near_deepest[lane] = leaf.depth[lane] >= floor ? -1 : 0;
  }
  for_each_lane(pack(near_deepest) & leaf.penetrating_lanes, [&](std::uint32_t lane) {
    const double depth = exact(lane);
    if (depth > leaf.max_depth_mm) {
      leaf.max_depth_mm = depth;
      leaf.deepest_lane = lane;
    }
  });
}

}  // namespace

LeafTip leaf_tip(const Eigen::Vector3d& tip_mm) {
  LeafTip tip{tip_mm, {}, {}};
  // The tip as a float and the float of what that leaves out: (p - high) - low is the offset to
  // within a rounding of its own size, however far the part is from the origin. The split is
  // Veltkamp's (tip = head + exactly the rest, head with a float's 24 bits): the plain
  // tip - double(float(tip)) is folded to 0 by GCC 12's vectorizer (x and y lost their rest;
  // LeafContacts.AnOffsetFromATipThatIsNotAFloatIsRightToARoundingOfItsOwnSize).
  constexpr double kVeltkamp = 536870913.0;  // 2^29 + 1: splits a double's 53 bits into 24 and 29
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const double value = tip_mm[static_cast<Eigen::Index>(axis)];
    const double scaled = kVeltkamp * value;
    const double head = scaled - (scaled - value);
    tip.high[axis] = static_cast<float>(head);
    tip.low[axis] = static_cast<float>(value - head);
  }
  return tip;
}

void bind_leaf(const tables::PartTables& part, const tables::LeafBlock& block, const LeafTip& tip, LeafContacts& leaf) {
  leaf.first = block.first_point;
  leaf.count = block.point_count;
  leaf.points = &part.points[block.first_point];
  leaf.normals = &block;
  leaf.tip_mm = tip.mm;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    leaf.tip_high[axis] = tip.high[axis];
    leaf.tip_low[axis] = tip.low[axis];
  }
  const Eigen::Vector3d& tip_mm = tip.mm;
  // Every point within the block's sphere: |p - tip|_1 <= |centre - tip|_1 + sqrt(3) radius, and a
  // lane's float offset within a rounding of the point's (the loader checked the sphere; a sphere
  // that is not finite makes every lane's depth be settled in double precision).
  const double bound = std::abs(double{block.centre_mm[0]} - tip_mm.x()) + std::abs(double{block.centre_mm[1]} - tip_mm.y()) +
                       std::abs(double{block.centre_mm[2]} - tip_mm.z()) + 1.7320508075688773 * double{block.radius_mm};
  leaf.magnitude_mm = std::isfinite(bound) ? static_cast<float>(bound * (1.0 + 1e-6)) : std::numeric_limits<float>::infinity();
}

void load_lanes(LeafContacts& leaf) {
  // The block's lanes are the leaf's points, the last repeated past count: plain vector loads, and
  // the normals are read where they are.
#if defined(__AVX2__)
  const TipLanes tip = tip_lanes(leaf);
  for (std::uint32_t base = 0; base < kLanes; base += 8) {
    const PointLanes p = point_lanes(leaf, tip, base);
    _mm256_storeu_ps(leaf.x.data() + base, p.x);
    _mm256_storeu_ps(leaf.y.data() + base, p.y);
    _mm256_storeu_ps(leaf.z.data() + base, p.z);
  }
#else
  const tables::LeafBlock& block = *leaf.normals;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    leaf.x[lane] = (block.x_mm[lane] - leaf.tip_high[0]) - leaf.tip_low[0];
    leaf.y[lane] = (block.y_mm[lane] - leaf.tip_high[1]) - leaf.tip_low[1];
    leaf.z[lane] = (block.z_mm[lane] - leaf.tip_high[2]) - leaf.tip_low[2];
  }
#endif
}

void load_leaf(const tables::PartTables& part, const tables::LeafBlock& block, const Eigen::Vector3d& tip_mm,
               LeafContacts& leaf) {
  bind_leaf(part, block, leaf_tip(tip_mm), leaf);
  load_lanes(leaf);
}

bool region_leaf_contacts(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside, LeafContacts& leaf) {
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
  if (!surface_contacts(surface, or_outside, leaf)) {
    return false;
  }
  summarise(band_for(leaf, surface), [&](std::uint32_t lane) { return exact_depth(leaf, lane, surface); }, leaf);
  return true;
}

namespace {

const geometry::ImplicitSurface* part_surface(const geometry::ToolBsp& tool, const geometry::BoxPart& part) {
  return part.cover == geometry::BoxCover::Outside ? nullptr : &tool.surfaces[tool.regions[part.region].surface];
}

bool part_contacts(const geometry::ImplicitSurface* surface, const geometry::BoxPart& part, LeafContacts& leaf) {
  if (surface == nullptr) {
    clear_contacts(leaf);
    return true;
  }
  return surface_contacts(*surface, part.cover == geometry::BoxCover::RegionOrOutside, leaf);
}

}  // namespace

bool split_leaf_contacts(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover, LeafContacts& leaf) {
  const geometry::ImplicitSurface* below = part_surface(tool, cover.below);
  const geometry::ImplicitSurface* above = part_surface(tool, cover.above);
  // classify_meridian's partition test, on the same double-precision z: below when z - split < 0.
  LaneMask is_below = 0;
  for (std::uint32_t lane = 0; lane < leaf.count; ++lane) {
    is_below |= exact_offset(leaf, lane).z - cover.split_z_mm < 0.0 ? LaneMask{1} << lane : 0U;
  }
  if (!part_contacts(below, cover.below, leaf)) {
    return false;
  }
  const LeafLanes depth = leaf.depth, ex = leaf.ex, ey = leaf.ey, ez = leaf.ez;
  const LaneMask below_in_tool = leaf.in_tool, below_penetrating = leaf.penetrating_lanes;
  if (!part_contacts(above, cover.above, leaf)) {
    return false;
  }
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    if ((is_below >> lane) & 1U) {
      leaf.depth[lane] = depth[lane];
      leaf.ex[lane] = ex[lane];
      leaf.ey[lane] = ey[lane];
      leaf.ez[lane] = ez[lane];
    }
  }
  leaf.in_tool = (below_in_tool & is_below) | (leaf.in_tool & ~is_below);
  leaf.penetrating_lanes = (below_penetrating & is_below) | (leaf.penetrating_lanes & ~is_below);
  const float band = std::max(below != nullptr ? band_for(leaf, *below) : 0.0F,
                              above != nullptr ? band_for(leaf, *above) : 0.0F);
  // Only penetrating lanes are asked for, and those have a surface on their own side.
  summarise(
      band,
      [&](std::uint32_t lane) {
        const geometry::ImplicitSurface* surface = ((is_below >> lane) & 1U) != 0 ? below : above;
        return surface != nullptr ? exact_depth(leaf, lane, *surface) : 0.0;
      },
      leaf);
  return true;
}

bool mixed_leaf_contacts(const geometry::ToolBsp& tool, LeafContacts& leaf) {
  LeafLanes r{}, radial{}, axial{};  // past count: zero, so no escape and no force
  std::array<double, kLanes> exact{};
  leaf.depth.fill(0.0F);
  leaf.in_tool = 0;
  leaf.penetrating_lanes = 0;
  for (std::uint32_t lane = 0; lane < leaf.count; ++lane) {
    // No outline pre-filter here: it would drop points touching the surface from just outside,
    // which the settled leaves keep; the tool tree decides them all alike, in double precision.
    const ExactOffset o = exact_offset(leaf, lane);
    const double r_exact = std::sqrt(o.x * o.x + o.y * o.y);
    const geometry::MeridianClassification c = geometry::classify_meridian(tool, {r_exact, o.z});
    if (c.contact == geometry::PointContact::BadTree) {
      return false;
    }
    const bool inside = c.contact != geometry::PointContact::Outside;
    const bool penetrating = c.contact == geometry::PointContact::Penetrating;
    r[lane] = static_cast<float>(r_exact);
    leaf.in_tool |= inside ? LaneMask{1} << lane : 0U;
    leaf.penetrating_lanes |= penetrating ? LaneMask{1} << lane : 0U;
    exact[lane] = penetrating ? c.depth_mm : 0.0;
    leaf.depth[lane] = penetrating ? static_cast<float>(c.depth_mm) : 0.0F;  // > 0: depth > 1e-9
    radial[lane] = inside ? static_cast<float>(c.escape.radial) : 0.0F;
    axial[lane] = inside ? static_cast<float>(c.escape.axial) : 0.0F;
  }
  escape_to_world(r, radial, axial, leaf);
  // The float depths are roundings of the exact ones: within a float ulp of the deepest.
  summarise(static_cast<float>(0x1p-23 * static_cast<double>(lane_max(leaf.depth))),
            [&](std::uint32_t lane) { return exact[lane]; }, leaf);
  return true;
}

LeafForceSums leaf_forces(const LeafContacts& leaf, double k_world, double centre_height_mm) {
  const auto k = static_cast<float>(k_world);
  const auto height = static_cast<float>(centre_height_mm);
  constexpr auto kNoDirectionF = static_cast<float>(kNoDirection);
  // Left to the compiler's vectoriser (an AVX2 version of this loop alone took more instructions);
  // the query's leaves in one region take region_leaf_force's fused pass instead, which saves the
  // stores between the steps.
  LeafLanes fx, fy, fz, tx, ty, tz;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
    const float vx = leaf.normals->nx[lane] - leaf.ex[lane];
    const float vy = leaf.normals->ny[lane] - leaf.ey[lane];
    const float vz = leaf.normals->nz[lane] - leaf.ez[lane];
    const float length = std::sqrt(vx * vx + vy * vy + vz * vz);
    // Zero where the normal and the escape direction cancel (no direction) or nothing penetrates.
    const float scale = length >= kNoDirectionF ? k * leaf.depth[lane] / length : 0.0F;
    fx[lane] = scale * vx;
    fy[lane] = scale * vy;
    fz[lane] = scale * vz;
    // About the compliance centre, up the axis from the tip: r = offset - (0, 0, height).
    const float rz = leaf.z[lane] - height;
    tx[lane] = leaf.y[lane] * fz[lane] - rz * fy[lane];
    ty[lane] = rz * fx[lane] - leaf.x[lane] * fz[lane];
    tz[lane] = leaf.x[lane] * fy[lane] - leaf.y[lane] * fx[lane];
  }
  return {Eigen::Vector3d(double{lane_sum(fx)}, double{lane_sum(fy)}, double{lane_sum(fz)}),
          Eigen::Vector3d(double{lane_sum(tx)}, double{lane_sum(ty)}, double{lane_sum(tz)})};
}

namespace {

#if defined(__AVX2__)
// The fused pass of region_leaf_force: each step the same operation, on the same operands and in
// the same order, as the loops of surface_contacts, summarise and leaf_forces (which the compiler
// vectorises lane for lane, -ffp-contract=off), so the same bits; only nothing is stored between.
__m256 splat(float value) { return _mm256_set1_ps(value); }

// lane_sum's horizontal step, on partial sums already in a register.
float reduce_sum(__m256 partial) {
  const __m128 q = _mm_add_ps(_mm256_castps256_ps128(partial), _mm256_extractf128_ps(partial, 1));
  const __m128 r = _mm_add_ps(q, _mm_movehl_ps(q, q));
  return _mm_cvtss_f32(_mm_add_ss(r, _mm_shuffle_ps(r, r, 1)));
}

// The surface's function and the escape direction of eight lanes (surface_contacts' first loop).
struct SurfaceLanes {
  __m256 f, ex, ey, ez;
};

struct SurfaceConstants {
  __m256 sign, centre_z, centre_r, radius;
};

// escape_to_world: radial along (x, y) / r, or along +y on the axis. std::max(r, k) is
// _mm256_max_ps(k, r) (the second operand when they compare equal or r is NaN, as std::max).
void escape_lanes(__m256 r, __m256 radial, __m256 axial, __m256 x, __m256 y, SurfaceLanes& s) {
  const __m256 on_axis = _mm256_cmp_ps(r, splat(kOnAxisRadius_mm), _CMP_NGT_UQ);
  const __m256 inverse = _mm256_div_ps(splat(1.0F), _mm256_max_ps(splat(kOnAxisRadius_mm), r));
  s.ex = _mm256_blendv_ps(_mm256_mul_ps(radial, _mm256_mul_ps(x, inverse)), _mm256_setzero_ps(), on_axis);
  s.ey = _mm256_blendv_ps(_mm256_mul_ps(radial, _mm256_mul_ps(y, inverse)), radial, on_axis);
  s.ez = axial;
}

__m256 radius_lanes(__m256 x, __m256 y) { return _mm256_sqrt_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y))); }

// The surface's function of eight lanes, with what its escape direction is made from: the one
// sqrt a depth needs, apart from the division the direction needs, so that a kernel can leave the
// direction out where no lane penetrates.
struct SurfaceFunction {
  __m256 f, length, r, dr, dz;  // length: from the centre (sphere, torus); r: from the axis (cylinder, torus)
};

template <SurfaceKind Kind>
[[gnu::always_inline]] inline SurfaceFunction surface_function_lanes(const SurfaceConstants& c, __m256 x, __m256 y, __m256 z) {
  SurfaceFunction s{};
  if constexpr (Kind == SurfaceKind::PlaneZ) {
    s.f = _mm256_sub_ps(z, c.centre_z);
  } else if constexpr (Kind == SurfaceKind::Cylinder) {
    s.r = radius_lanes(x, y);
    s.f = _mm256_sub_ps(s.r, c.radius);
  } else if constexpr (Kind == SurfaceKind::Sphere) {
    s.dz = _mm256_sub_ps(z, c.centre_z);
    s.length = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)), _mm256_mul_ps(s.dz, s.dz)));
    s.f = _mm256_sub_ps(s.length, c.radius);
  } else {
    s.r = radius_lanes(x, y);
    s.dr = _mm256_sub_ps(s.r, c.centre_r);
    s.dz = _mm256_sub_ps(z, c.centre_z);
    s.length = _mm256_sqrt_ps(_mm256_add_ps(_mm256_mul_ps(s.dr, s.dr), _mm256_mul_ps(s.dz, s.dz)));
    s.f = _mm256_sub_ps(s.length, c.radius);
  }
  return s;
}

template <SurfaceKind Kind>
[[gnu::always_inline]] inline SurfaceLanes escape_of(const SurfaceConstants& c, const SurfaceFunction& f, __m256 x, __m256 y) {
  SurfaceLanes s{};
  s.f = f.f;
  if constexpr (Kind == SurfaceKind::PlaneZ) {
    s.ex = _mm256_setzero_ps();
    s.ey = _mm256_setzero_ps();
    s.ez = c.sign;
  } else if constexpr (Kind == SurfaceKind::Cylinder) {
    escape_lanes(f.r, c.sign, _mm256_setzero_ps(), x, y, s);
  } else if constexpr (Kind == SurfaceKind::Sphere) {
    const __m256 degenerate = _mm256_cmp_ps(f.length, splat(kDegenerateDistance_mm), _CMP_NGE_UQ);
    const __m256 inverse = _mm256_div_ps(c.sign, _mm256_max_ps(splat(kDegenerateDistance_mm), f.length));
    s.ex = _mm256_blendv_ps(_mm256_mul_ps(x, inverse), _mm256_setzero_ps(), degenerate);
    s.ey = _mm256_blendv_ps(_mm256_mul_ps(y, inverse), splat(kInvSqrt2), degenerate);
    s.ez = _mm256_blendv_ps(_mm256_mul_ps(f.dz, inverse), splat(-kInvSqrt2), degenerate);
  } else {
    const __m256 degenerate = _mm256_cmp_ps(f.length, splat(kDegenerateDistance_mm), _CMP_NGE_UQ);
    const __m256 inverse = _mm256_div_ps(c.sign, _mm256_max_ps(splat(kDegenerateDistance_mm), f.length));
    const __m256 radial = _mm256_blendv_ps(_mm256_mul_ps(f.dr, inverse), splat(kInvSqrt2), degenerate);
    const __m256 axial = _mm256_blendv_ps(_mm256_mul_ps(f.dz, inverse), splat(-kInvSqrt2), degenerate);
    escape_lanes(f.r, radial, axial, x, y, s);
  }
  return s;
}

template <SurfaceKind Kind>
SurfaceLanes surface_lanes(const SurfaceConstants& c, __m256 x, __m256 y, __m256 z) {
  return escape_of<Kind>(c, surface_function_lanes<Kind>(c, x, y, z), x, y);
}

// leaf_forces' arithmetic over eight lanes at a time, summed into eight partials per component.
struct LaneForces {
  __m256 k, height, no_direction;
  __m256 fx = _mm256_setzero_ps(), fy = _mm256_setzero_ps(), fz = _mm256_setzero_ps();
  __m256 tx = _mm256_setzero_ps(), ty = _mm256_setzero_ps(), tz = _mm256_setzero_ps();

  LaneForces(double k_world, double centre_height_mm)
      : k(splat(static_cast<float>(k_world))),
        height(splat(static_cast<float>(centre_height_mm))),
        no_direction(splat(static_cast<float>(kNoDirection))) {}

  // Lanes base..base+7 of the leaf: offsets x, y, z, depth d (0 where it does not penetrate) and
  // escape direction e.
  [[gnu::always_inline]] inline void add(const LeafContacts& leaf, std::uint32_t base, __m256 x, __m256 y, __m256 z, __m256 d, const SurfaceLanes& e) {
    const __m256 vx = _mm256_sub_ps(_mm256_loadu_ps(leaf.normals->nx + base), e.ex);
    const __m256 vy = _mm256_sub_ps(_mm256_loadu_ps(leaf.normals->ny + base), e.ey);
    const __m256 vz = _mm256_sub_ps(_mm256_loadu_ps(leaf.normals->nz + base), e.ez);
    const __m256 length = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(vx, vx), _mm256_mul_ps(vy, vy)), _mm256_mul_ps(vz, vz)));
    const __m256 scale = _mm256_and_ps(_mm256_cmp_ps(length, no_direction, _CMP_GE_OQ),
                                       _mm256_div_ps(_mm256_mul_ps(k, d), length));
    const __m256 lane_fx = _mm256_mul_ps(scale, vx), lane_fy = _mm256_mul_ps(scale, vy), lane_fz = _mm256_mul_ps(scale, vz);
    const __m256 rz = _mm256_sub_ps(z, height);
    fx = _mm256_add_ps(fx, lane_fx);
    fy = _mm256_add_ps(fy, lane_fy);
    fz = _mm256_add_ps(fz, lane_fz);
    tx = _mm256_add_ps(tx, _mm256_sub_ps(_mm256_mul_ps(y, lane_fz), _mm256_mul_ps(rz, lane_fy)));
    ty = _mm256_add_ps(ty, _mm256_sub_ps(_mm256_mul_ps(rz, lane_fx), _mm256_mul_ps(x, lane_fz)));
    tz = _mm256_add_ps(tz, _mm256_sub_ps(_mm256_mul_ps(x, lane_fy), _mm256_mul_ps(y, lane_fx)));
  }

  [[nodiscard]] LeafForceSums sums() const {
    return {Eigen::Vector3d(double{reduce_sum(fx)}, double{reduce_sum(fy)}, double{reduce_sum(fz)}),
            Eigen::Vector3d(double{reduce_sum(tx)}, double{reduce_sum(ty)}, double{reduce_sum(tz)})};
  }
};

// The depth of lanes past count is 0 (summarise): the mask of lanes base..base+7 below count.
[[gnu::always_inline]] inline __m256 below_count(const LeafContacts& leaf, std::uint32_t base) {
  const __m256i index = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(base)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  return _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(leaf.count)), index));
}

// summarise's search for the deepest lane: of the penetrating lanes, those whose float depth is
// within twice the band of the largest, each in double precision (exact(lane)); the first at the
// greatest depth. The candidates are picked eight lanes to a compare, the same test as lane by lane.
template <typename ExactDepth>
void find_deepest_lane(const LeafLanes& depths, float band, LaneMask penetrating, ExactDepth&& exact,
                       RegionLeafForce& out) {
  const __m256 floor = splat(lane_max(depths) - 2.0F * band);
  LaneMask near_deepest = 0;
  for (std::uint32_t base = 0; base < kLanes; base += 8) {
    near_deepest |= static_cast<LaneMask>(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_load_ps(depths.data() + base), floor, _CMP_GE_OQ)))
                    << base;
  }
  for_each_lane(near_deepest & penetrating, [&](std::uint32_t lane) {
    const double depth = exact(lane);
    if (depth > out.max_depth_mm) {
      out.max_depth_mm = depth;
      out.deepest_lane = lane;
    }
  });
}

// One region's verdicts on eight lanes (surface_contacts' second loop): the depth where it
// penetrates beyond the tolerance, else 0; the lanes in `check_lanes` whose float depth is within
// the band settled again in double precision (`depths` is scratch for them). Adds the lanes'
// function to `check` and sets their bits in `penetrating`.
struct RegionVerdicts {
  const geometry::ImplicitSurface* surface;
  __m256 minus_sign, tolerance, band, no_sign;
};
[[gnu::always_inline]] inline __m256 region_depths(const RegionVerdicts& v, const LeafContacts& leaf, std::uint32_t base, __m256 f,
                     LaneMask check_lanes, __m256& check, LaneMask& penetrating, LeafLanes& depths) {
  const __m256 depth = _mm256_mul_ps(v.minus_sign, f);
  const __m256 deeper = _mm256_cmp_ps(depth, v.tolerance, _CMP_GT_OQ);
  __m256 d = _mm256_and_ps(deeper, depth);
  // The function alone tells a lane that is not finite: the offsets are finite (finite points and
  // tip, millimetres from each other), so the escape direction is (a division by at least 1e-12),
  // and what can make a lane's numbers non-finite is the surface's, which reach its function.
  check = _mm256_add_ps(check, f);
  penetrating |= static_cast<LaneMask>(_mm256_movemask_ps(deeper)) << base;
  const LaneMask uncertain =
      (static_cast<LaneMask>(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_and_ps(depth, v.no_sign), v.band, _CMP_LE_OQ)))
       << base) & check_lanes;
  if (uncertain != 0) {
    _mm256_store_ps(depths.data() + base, d);
    for_each_lane(uncertain, [&](std::uint32_t lane) {
      const double exact = exact_depth(leaf, lane, *v.surface);
      const bool is_deeper = exact > geometry::kSurfaceTolerance_mm;
      depths[lane] = is_deeper ? static_cast<float>(exact) : 0.0F;
      penetrating = is_deeper ? penetrating | (LaneMask{1} << lane) : penetrating & ~(LaneMask{1} << lane);
    });
    d = _mm256_load_ps(depths.data() + base);
  }
  return d;
}

SurfaceConstants constants_of(const geometry::ImplicitSurface& surface) {
  const float sign = surface.solid_side == geometry::SolidSide::Below ? 1.0F : -1.0F;
  return {splat(sign), splat(static_cast<float>(surface.center_z_mm)), splat(static_cast<float>(surface.center_r_mm)),
          splat(static_cast<float>(surface.radius_mm))};
}

RegionVerdicts verdicts_of(const geometry::ImplicitSurface& surface, float band) {
  const float sign = surface.solid_side == geometry::SolidSide::Below ? 1.0F : -1.0F;
  return {&surface, splat(-sign), splat(kTolerance_mm), splat(band), _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff))};
}

// The block's four groups at their centroids, one to each double lane of an AVX register: the
// offset from the tip, the distance r from the axis, and from the region's surface the depth, how
// fast the escape direction turns (1 / its radius of curvature) and the escape direction, by the
// same operations as block_point, interior_distance and escape_direction. Groups past the leaf's
// points are zeros and give numbers of no meaning.
struct GroupGeometry {
  __m256d px, py, pz, ox, oy, oz, r, depth, curvature, escape_radial, escape_axial;
};
template <SurfaceKind Kind>
[[gnu::always_inline]] inline GroupGeometry group_geometry(const geometry::ImplicitSurface& surface,
                                                           const tables::LeafBlock& block, const Eigen::Vector3d& tip_mm) {
  static_assert(tables::kLeafGroups == 4, "one group to each double lane of an AVX register");
  const auto lanes = [](const float (&four)[tables::kLeafGroups]) { return _mm256_cvtps_pd(_mm_loadu_ps(four)); };
  const auto splat_d = [](double value) { return _mm256_set1_pd(value); };
  const __m256d px = lanes(block.group_centroid_mm[0]), py = lanes(block.group_centroid_mm[1]),
                pz = lanes(block.group_centroid_mm[2]);
  const __m256d ox = _mm256_sub_pd(px, splat_d(tip_mm.x())), oy = _mm256_sub_pd(py, splat_d(tip_mm.y())),
                oz = _mm256_sub_pd(pz, splat_d(tip_mm.z()));
  const __m256d r = _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(ox, ox), _mm256_mul_pd(oy, oy)));
  const double side = surface.solid_side == geometry::SolidSide::Below ? 1.0 : -1.0;
  __m256d f, curvature, escape_radial, escape_axial;
  if constexpr (Kind == SurfaceKind::PlaneZ) {
    f = _mm256_sub_pd(oz, splat_d(surface.center_z_mm));
    curvature = _mm256_setzero_pd();
    escape_radial = _mm256_setzero_pd();
    escape_axial = splat_d(side);
  } else if constexpr (Kind == SurfaceKind::Cylinder) {
    f = _mm256_sub_pd(r, splat_d(surface.radius_mm));
    curvature = _mm256_div_pd(splat_d(1.0), r);
    escape_radial = splat_d(side);
    escape_axial = _mm256_setzero_pd();
  } else {
    const __m256d dr = _mm256_sub_pd(r, splat_d(Kind == SurfaceKind::Torus ? surface.center_r_mm : 0.0));
    const __m256d dz = _mm256_sub_pd(oz, splat_d(surface.center_z_mm));
    const __m256d tube = _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(dr, dr), _mm256_mul_pd(dz, dz)));
    f = _mm256_sub_pd(tube, splat_d(surface.radius_mm));
    const __m256d to_axis_sq = _mm256_mul_pd(r, r);
    if constexpr (Kind == SurfaceKind::Sphere) {
      curvature = _mm256_div_pd(splat_d(1.0), _mm256_sqrt_pd(_mm256_add_pd(to_axis_sq, _mm256_mul_pd(dz, dz))));
    } else {  // std::min(r^2, dr^2 + dz^2): the second only where it is less
      const __m256d to_tube_sq = _mm256_add_pd(_mm256_mul_pd(dr, dr), _mm256_mul_pd(dz, dz));
      curvature = _mm256_div_pd(
          splat_d(1.0),
          _mm256_sqrt_pd(_mm256_blendv_pd(to_axis_sq, to_tube_sq, _mm256_cmp_pd(to_tube_sq, to_axis_sq, _CMP_LT_OQ))));
    }
    const __m256d degenerate = _mm256_cmp_pd(tube, splat_d(1e-12), _CMP_LT_OQ);  // escape_direction's
    escape_radial = _mm256_blendv_pd(_mm256_div_pd(_mm256_mul_pd(splat_d(side), dr), tube),
                                     splat_d(0.70710678118654752440), degenerate);
    escape_axial = _mm256_blendv_pd(_mm256_div_pd(_mm256_mul_pd(splat_d(side), dz), tube),
                                    splat_d(-0.70710678118654752440), degenerate);
  }
  return {px, py, pz, ox, oy, oz, r, _mm256_mul_pd(splat_d(-side), f), curvature, escape_radial, escape_axial};
}

// The groups of a leaf in one region that no point of can penetrate (its depth at the centroid
// plus its radius, the depth changing no faster than the point moves, is within the tolerance), or
// reach floor_mm (-infinity: none), and the groups past its points: bit g for group g.
template <SurfaceKind Kind>
[[gnu::always_inline]] inline unsigned shallow_groups(const geometry::ImplicitSurface& surface, const LeafContacts& leaf,
                                                      double floor_mm) {
  const tables::LeafBlock& block = *leaf.normals;
  const GroupGeometry g = group_geometry<Kind>(surface, block, leaf.tip_mm);
  // A margin for the rounding of the one depth: about 1e-13 mm for a workspace a metre across.
  const __m256d deepest = _mm256_add_pd(_mm256_add_pd(g.depth, _mm256_cvtps_pd(_mm_loadu_ps(block.group_radius_mm))),
                                        _mm256_set1_pd(1e-9));
  // Not where the depth is not finite (a damaged surface): those lanes are computed, and their
  // check fails.
  const __m256d finite = _mm256_cmp_pd(_mm256_and_pd(deepest, _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffff))),
                                       _mm256_set1_pd(std::numeric_limits<double>::max()), _CMP_LE_OQ);
  const __m256d below = _mm256_or_pd(_mm256_cmp_pd(deepest, _mm256_set1_pd(geometry::kSurfaceTolerance_mm), _CMP_LE_OQ),
                                     _mm256_cmp_pd(deepest, _mm256_set1_pd(floor_mm), _CMP_LT_OQ));
  const unsigned shallow = static_cast<unsigned>(_mm256_movemask_pd(_mm256_and_pd(finite, below)));
  const unsigned groups = (leaf.count + tables::kLeafGroupPoints - 1) / tables::kLeafGroupPoints;
  return shallow | (0xFU & ~((1U << groups) - 1U));
}

// kForce false: the depths and the deepest lane alone (region_leaf_deepest), no direction or force,
// leaving out the groups that cannot reach floor_mm as if shallow.
template <SurfaceKind Kind, bool kForce = true>
bool region_force_lanes(const geometry::ImplicitSurface& surface, bool find_deepest, double k_world,
                        double centre_height_mm, const LeafContacts& leaf, RegionLeafForce& out,
                        double floor_mm = -std::numeric_limits<double>::infinity()) {
  const SurfaceConstants c = constants_of(surface);
  const float band = band_for(leaf, surface);
  const RegionVerdicts verdicts = verdicts_of(surface, band);
  const LaneMask valid = lanes_below(leaf.count);
  alignas(32) LeafLanes depths;
  __m256 check = _mm256_setzero_ps();
  LaneForces forces(k_world, centre_height_mm);
  LaneMask penetrating = 0;
  // A group that cannot penetrate adds nothing: its lanes' depths are 0 either way (within the
  // band of the surface they would be settled in double precision, below it), so their forces.
  const unsigned shallow =
      shallow_groups<Kind>(surface, leaf, kForce ? -std::numeric_limits<double>::infinity() : floor_mm);
  const TipLanes tip = tip_lanes(leaf);
  const bool full = leaf.count >= kLanes;  // no lane past the count to clear
  for (std::uint32_t base = 0; base < kLanes; base += 8) {
    if (((shallow >> (base / tables::kLeafGroupPoints)) & 1U) != 0) {
      _mm256_store_ps(depths.data() + base, _mm256_setzero_ps());
      continue;
    }
    const PointLanes p = point_lanes(leaf, tip, base);  // the lanes load_lanes would store, not stored
    const __m256 x = p.x, y = p.y, z = p.z;
    const SurfaceFunction f = surface_function_lanes<Kind>(c, x, y, z);
    const __m256 raw = region_depths(verdicts, leaf, base, f.f, valid, check, penetrating, depths);
    const __m256 d = full ? raw : _mm256_and_ps(below_count(leaf, base), raw);
    _mm256_store_ps(depths.data() + base, d);
    // Eight lanes none of which penetrates add only zeros to the sums (with k and the centre's
    // height finite, as the skip of shallow groups above already takes them), which are never -0
    // (they start at +0, and x + -x is +0 rounding to nearest): the same bits without their escape
    // directions and forces.
    if (!kForce || _mm256_movemask_ps(_mm256_cmp_ps(d, _mm256_setzero_ps(), _CMP_NEQ_UQ)) == 0) {
      continue;
    }
    forces.add(leaf, base, x, y, z, d, escape_of<Kind>(c, f, x, y));
  }
  if (!std::isfinite(reduce_sum(check))) {
    return false;
  }
  out.penetrating = static_cast<std::uint32_t>(std::popcount(penetrating & valid));
  out.max_depth_mm = 0.0;
  out.deepest_lane = 0;
  if (find_deepest && out.penetrating > 0) {
    find_deepest_lane(depths, band, penetrating & valid, [&](std::uint32_t lane) { return exact_depth(leaf, lane, surface); },
                      out);
  }
  out.sums = forces.sums();
  return true;
}

[[gnu::always_inline]] inline SurfaceLanes any_surface_lanes(SurfaceKind kind, const SurfaceConstants& c, __m256 x, __m256 y, __m256 z) {
  switch (kind) {
    case SurfaceKind::PlaneZ:
      return surface_lanes<SurfaceKind::PlaneZ>(c, x, y, z);
    case SurfaceKind::Cylinder:
      return surface_lanes<SurfaceKind::Cylinder>(c, x, y, z);
    case SurfaceKind::Sphere:
      return surface_lanes<SurfaceKind::Sphere>(c, x, y, z);
    case SurfaceKind::Torus:
      break;
  }
  return surface_lanes<SurfaceKind::Torus>(c, x, y, z);
}

// One side of a split leaf: its region's surface (none: outside the tool) and its verdicts so far.
struct SplitSide {
  const geometry::ImplicitSurface* surface;
  float band;  // 0 with no surface: split_leaf_contacts' maximum of the two sides' bands
  SurfaceConstants c;
  RegionVerdicts verdicts;
  __m256 check = _mm256_setzero_ps();
  LaneMask penetrating = 0;

  SplitSide(const geometry::ImplicitSurface* side_surface, const LeafContacts& leaf)
      : surface(side_surface),
        band(side_surface != nullptr ? band_for(leaf, *side_surface) : 0.0F),
        c(side_surface != nullptr ? constants_of(*side_surface) : SurfaceConstants{}),
        verdicts(side_surface != nullptr ? verdicts_of(*side_surface, band) : RegionVerdicts{}) {}

  // Depth and escape of lanes base..base+7 from this side's surface (zero with none, as
  // clear_contacts leaves them); of its own lanes, `mine`, those on the surface settled in double
  // precision as surface_contacts settles them (the other side's lanes are not used).
  __m256 lanes(const LeafContacts& leaf, std::uint32_t base, __m256 x, __m256 y, __m256 z, LaneMask mine,
               LeafLanes& depths, SurfaceLanes& s) {
    if (surface == nullptr) {
      s = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
      return _mm256_setzero_ps();
    }
    s = any_surface_lanes(surface->kind, c, x, y, z);
    return region_depths(verdicts, leaf, base, s.f, mine, check, penetrating, depths);
  }

  [[nodiscard]] bool finite() const { return surface == nullptr || std::isfinite(reduce_sum(check)); }
};

// split_leaf_contacts then leaf_forces, in one pass: each lane takes its own side's depth and
// escape, then the force of region_force_lanes.
bool split_force_lanes(const geometry::ImplicitSurface* below_surface, const geometry::ImplicitSurface* above_surface,
                       double split_z_mm, bool find_deepest, double k_world, double centre_height_mm,
                       const LeafContacts& leaf, RegionLeafForce& out) {
  SplitSide below(below_surface, leaf), above(above_surface, leaf);
  const LaneMask valid = lanes_below(leaf.count);
  // classify_meridian's partition test, on the same double-precision z: below when z - split < 0
  // (the block's lanes are the points' own floats).
  const __m256d tip_z = _mm256_set1_pd(leaf.tip_mm.z()), split_z = _mm256_set1_pd(split_z_mm);
  const auto below_split = [&](__m128 four_z) {
    return _mm256_movemask_pd(_mm256_cmp_pd(_mm256_sub_pd(_mm256_sub_pd(_mm256_cvtps_pd(four_z), tip_z), split_z),
                                            _mm256_setzero_pd(), _CMP_LT_OQ));
  };
  const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  alignas(32) LeafLanes depths;
  LaneForces forces(k_world, centre_height_mm);
  LaneMask is_below = 0;
  const TipLanes tip = tip_lanes(leaf);
  for (std::uint32_t base = 0; base < kLanes; base += 8) {
    const PointLanes p = point_lanes(leaf, tip, base);
    const __m256 x = p.x, y = p.y, z = p.z;
    const __m256 point_z = _mm256_loadu_ps(leaf.normals->z_mm + base);
    const auto chunk = static_cast<std::uint32_t>(below_split(_mm256_castps256_ps128(point_z)) |
                                                  (below_split(_mm256_extractf128_ps(point_z, 1)) << 4));
    const LaneMask chunk_below = (static_cast<LaneMask>(chunk) << base) & valid;
    is_below |= chunk_below;
    SurfaceLanes below_lanes{}, above_lanes{};
    const __m256 below_d = below.lanes(leaf, base, x, y, z, chunk_below, depths, below_lanes);
    const __m256 above_d = above.lanes(leaf, base, x, y, z, valid & ~chunk_below, depths, above_lanes);
    const __m256i chunk_bits = _mm256_set1_epi32(static_cast<int>(chunk_below >> base));
    const __m256 take_below = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(chunk_bits, lane_bit), lane_bit));
    const SurfaceLanes s{_mm256_setzero_ps(), _mm256_blendv_ps(above_lanes.ex, below_lanes.ex, take_below),
                         _mm256_blendv_ps(above_lanes.ey, below_lanes.ey, take_below),
                         _mm256_blendv_ps(above_lanes.ez, below_lanes.ez, take_below)};
    const __m256 d = _mm256_and_ps(below_count(leaf, base), _mm256_blendv_ps(above_d, below_d, take_below));
    _mm256_store_ps(depths.data() + base, d);
    forces.add(leaf, base, x, y, z, d, s);
  }
  if (!below.finite() || !above.finite()) {
    return false;
  }
  const LaneMask penetrating = ((below.penetrating & is_below) | (above.penetrating & ~is_below)) & valid;
  out.penetrating = static_cast<std::uint32_t>(std::popcount(penetrating));
  out.max_depth_mm = 0.0;
  out.deepest_lane = 0;
  if (find_deepest && out.penetrating > 0) {
    // Only penetrating lanes are asked for, and those have a surface on their own side.
    find_deepest_lane(depths, std::max(below.band, above.band), penetrating,
                      [&](std::uint32_t lane) {
                        return exact_depth(leaf, lane, ((is_below >> lane) & 1U) != 0 ? *below.surface : *above.surface);
                      },
                      out);
  }
  out.sums = forces.sums();
  return true;
}
#endif

}  // namespace

#if !defined(__AVX2__)
namespace {

// The baseline build's answer from a leaf settled in two steps (its deepest lane is searched either
// way; the answer is the same).
RegionLeafForce settled_leaf_force(const LeafContacts& leaf, bool find_deepest, double k_world, double centre_height_mm) {
  return {leaf.penetrating, find_deepest ? leaf.max_depth_mm : 0.0, find_deepest ? leaf.deepest_lane : 0U,
          leaf_forces(leaf, k_world, centre_height_mm)};
}

}  // namespace
#endif

bool region_leaf_force(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside, bool find_deepest,
                       double k_world, double centre_height_mm, LeafContacts& leaf, RegionLeafForce& out) {
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
#if defined(__AVX2__)
  static_cast<void>(or_outside);  // only the touching lanes depend on it, and the force has none
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return region_force_lanes<SurfaceKind::PlaneZ>(surface, find_deepest, k_world, centre_height_mm, leaf, out);
    case SurfaceKind::Cylinder:
      return region_force_lanes<SurfaceKind::Cylinder>(surface, find_deepest, k_world, centre_height_mm, leaf, out);
    case SurfaceKind::Sphere:
      return region_force_lanes<SurfaceKind::Sphere>(surface, find_deepest, k_world, centre_height_mm, leaf, out);
    case SurfaceKind::Torus:
      return region_force_lanes<SurfaceKind::Torus>(surface, find_deepest, k_world, centre_height_mm, leaf, out);
  }
  return false;
#else
  // The rig's baseline build (x86-64-v2): the two steps on the walk's own leaf, as before the
  // fused pass.
  static_cast<void>(surface);
  load_lanes(leaf);
  if (!region_leaf_contacts(tool, region, or_outside, leaf)) {
    return false;
  }
  out = settled_leaf_force(leaf, find_deepest, k_world, centre_height_mm);
  return true;
#endif
}

bool region_leaf_deepest(const geometry::ToolBsp& tool, std::uint8_t region, double floor_mm, LeafContacts& leaf,
                         RegionLeafForce& out) {
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
#if defined(__AVX2__)
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return region_force_lanes<SurfaceKind::PlaneZ, false>(surface, true, 0.0, 0.0, leaf, out, floor_mm);
    case SurfaceKind::Cylinder:
      return region_force_lanes<SurfaceKind::Cylinder, false>(surface, true, 0.0, 0.0, leaf, out, floor_mm);
    case SurfaceKind::Sphere:
      return region_force_lanes<SurfaceKind::Sphere, false>(surface, true, 0.0, 0.0, leaf, out, floor_mm);
    case SurfaceKind::Torus:
      return region_force_lanes<SurfaceKind::Torus, false>(surface, true, 0.0, 0.0, leaf, out, floor_mm);
  }
  return false;
#else
  static_cast<void>(surface);
  static_cast<void>(floor_mm);  // every group taken: the lanes' answer leaves none out
  load_lanes(leaf);
  if (!region_leaf_contacts(tool, region, false, leaf)) {
    return false;
  }
  out = {leaf.penetrating, leaf.penetrating > 0 ? leaf.max_depth_mm : 0.0, leaf.deepest_lane,
         {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}};
  return true;
#endif
}

bool split_leaf_force(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover, bool find_deepest,
                      double k_world, double centre_height_mm, LeafContacts& leaf, RegionLeafForce& out) {
#if defined(__AVX2__)
  const geometry::ImplicitSurface* below = part_surface(tool, cover.below);
  const geometry::ImplicitSurface* above = part_surface(tool, cover.above);
  const auto known = [](const geometry::ImplicitSurface* surface) {
    return surface == nullptr || surface->kind == SurfaceKind::PlaneZ || surface->kind == SurfaceKind::Cylinder ||
           surface->kind == SurfaceKind::Sphere || surface->kind == SurfaceKind::Torus;
  };
  if (!known(below) || !known(above)) {
    return false;  // as surface_contacts: a damaged tree
  }
  return split_force_lanes(below, above, cover.split_z_mm, find_deepest, k_world, centre_height_mm, leaf, out);
#else
  load_lanes(leaf);
  if (!split_leaf_contacts(tool, cover, leaf)) {
    return false;
  }
  out = settled_leaf_force(leaf, find_deepest, k_world, centre_height_mm);
  return true;
#endif
}

namespace {

// A point of the block (its centroid or its sphere's centre) as the upright tool at tip_mm sees it.
struct BlockPoint {
  Eigen::Vector3d point;   // world mm
  Eigen::Vector3d offset;  // from the tip
  geometry::MeridianPoint meridian;
};
BlockPoint block_point(const float (&point_mm)[3], const Eigen::Vector3d& tip_mm) {
  const Eigen::Vector3d point(point_mm[0], point_mm[1], point_mm[2]);
  const Eigen::Vector3d offset = point - tip_mm;
  return {point, offset, {std::sqrt(offset.x() * offset.x() + offset.y() * offset.y()), offset.z()}};
}

}  // namespace

double leaf_deepest_bound(const geometry::ImplicitSurface& surface, const tables::LeafBlock& block,
                          const Eigen::Vector3d& tip_mm) {
  return geometry::interior_distance(surface, block_point(block.centre_mm, tip_mm).meridian) +
         double{block.radius_mm} + 1e-9;
}

namespace {

// The points whose moments are taken: a whole leaf or one group of its lanes.
struct Moments {
  float centroid_mm[3];
  float mean_normal[3];
  float radius_mm;  // every point within it of a point near the centroid (the leaf's sphere, or the group's own)
  std::uint32_t count;
};

// leaf_moment_force of one set of points (below).
LeafMomentForce moment_force(const geometry::ImplicitSurface& surface, const Moments& moments,
                             const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& centre, double k_world) {
  const double nx = moments.mean_normal[0], ny = moments.mean_normal[1], nz = moments.mean_normal[2];
  const BlockPoint at_centroid = block_point(moments.centroid_mm, tip_mm);
  const Eigen::Vector3d& offset = at_centroid.offset;
  const geometry::MeridianPoint meridian = at_centroid.meridian;
  const double r = meridian.r_mm;
  const double depth = geometry::interior_distance(surface, meridian);
  // How fast the escape direction turns at the centroid (1 / its radius of curvature): about the
  // axis with 1 / r, about a sphere's or a torus tube's centre with 1 / the distance to it.
  double curvature = 0.0;
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      break;
    case SurfaceKind::Cylinder:
      curvature = 1.0 / r;
      break;
    case SurfaceKind::Sphere: {  // centred on the axis: the distance to its centre alone
      const double dz = offset.z() - surface.center_z_mm;
      curvature = 1.0 / std::sqrt(r * r + dz * dz);
      break;
    }
    case SurfaceKind::Torus: {
      const double dr = r - surface.center_r_mm;
      const double dz = offset.z() - surface.center_z_mm;
      curvature = 1.0 / std::sqrt(std::min(r * r, dr * dr + dz * dz));
      break;
    }
  }
  const geometry::MeridianDirection escape = geometry::escape_direction(surface, meridian);
  // Radially out along (x, y) / r, or along +y on the axis, as the lanes and classify_at_pose turn it.
  const double radial_x = r > 1e-12 ? offset.x() / r : 0.0;
  const double radial_y = r > 1e-12 ? offset.y() / r : 1.0;
  const double vx = nx - (escape.radial * radial_x + escape.axial * 0.0);
  const double vy = ny - (escape.radial * radial_y + escape.axial * 0.0);
  const double vz = nz - (escape.radial * 0.0 + escape.axial * 1.0);
  const double length = std::sqrt((vx * vx + vy * vy) + vz * vz);
  const double normal_length = std::sqrt((nx * nx + ny * ny) + nz * nz);
  const double spread_sq = 0.25 * double{moments.radius_mm} * double{moments.radius_mm};
  if (!(depth > 0.0 && length >= kNoDirection && 2.0 * (1.0 - normal_length) <= kMomentError * length &&
        spread_sq * curvature * length * (length + 2.0) + spread_sq * curvature * curvature * depth <=
            2.0 * kMomentError * depth * length * length)) {
    return {false, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  const Eigen::Vector3d force = (k_world * static_cast<double>(moments.count) * depth / length) * Eigen::Vector3d(vx, vy, vz);
  return {true, force, (at_centroid.point - centre).cross(force)};
}

#if defined(__AVX2__)
// moment_force of the block's four groups at once, one to each double lane of an AVX register: the
// same operations in the same order, group by group, so the same numbers as the groups one by one
// (the baseline build's loop below). Settled only if every group with points is.
template <SurfaceKind Kind>
LeafMomentForce group_moment_lanes(const geometry::ImplicitSurface& surface, const tables::LeafBlock& block,
                                   const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& centre, double k_world) {
  static_assert(tables::kLeafGroups == 4, "one group to each double lane of an AVX register");
  const auto lanes = [](const float (&four)[tables::kLeafGroups]) { return _mm256_cvtps_pd(_mm_loadu_ps(four)); };
  const auto splat_d = [](double value) { return _mm256_set1_pd(value); };
  const __m256d n = _mm256_setr_pd(group_count(block, 0), group_count(block, 1), group_count(block, 2), group_count(block, 3));
  const __m256d present = _mm256_cmp_pd(n, _mm256_setzero_pd(), _CMP_GT_OQ);
  const __m256d nx = lanes(block.group_mean_normal[0]), ny = lanes(block.group_mean_normal[1]),
                nz = lanes(block.group_mean_normal[2]);
  const GroupGeometry g = group_geometry<Kind>(surface, block, tip_mm);
  const __m256d &px = g.px, &py = g.py, &pz = g.pz, &ox = g.ox, &oy = g.oy, &r = g.r, &depth = g.depth,
                &curvature = g.curvature, &escape_radial = g.escape_radial, &escape_axial = g.escape_axial;
  // Radially out along (x, y) / r, or along +y on the axis.
  const __m256d off_axis = _mm256_cmp_pd(r, splat_d(1e-12), _CMP_GT_OQ);
  const __m256d radial_x = _mm256_and_pd(off_axis, _mm256_div_pd(ox, r));
  const __m256d radial_y = _mm256_blendv_pd(splat_d(1.0), _mm256_div_pd(oy, r), off_axis);
  const __m256d zero = _mm256_setzero_pd();
  const __m256d dx = _mm256_sub_pd(nx, _mm256_add_pd(_mm256_mul_pd(escape_radial, radial_x), _mm256_mul_pd(escape_axial, zero)));
  const __m256d dy = _mm256_sub_pd(ny, _mm256_add_pd(_mm256_mul_pd(escape_radial, radial_y), _mm256_mul_pd(escape_axial, zero)));
  const __m256d dz = _mm256_sub_pd(nz, _mm256_add_pd(_mm256_mul_pd(escape_radial, zero), _mm256_mul_pd(escape_axial, splat_d(1.0))));
  const auto length_of = [](__m256d x, __m256d y, __m256d z) {
    return _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z)));
  };
  const __m256d length = length_of(dx, dy, dz);
  const __m256d normal_length = length_of(nx, ny, nz);
  const __m256d radius = lanes(block.group_radius_mm);
  const __m256d spread_sq = _mm256_mul_pd(_mm256_mul_pd(splat_d(0.25), radius), radius);
  const __m256d spread_curvature = _mm256_mul_pd(spread_sq, curvature);
  const __m256d error = _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(spread_curvature, length), _mm256_add_pd(length, splat_d(2.0))),
                                      _mm256_mul_pd(_mm256_mul_pd(spread_curvature, curvature), depth));
  const __m256d allowed = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(splat_d(2.0 * kMomentError), depth), length), length);
  const __m256d normals = _mm256_cmp_pd(_mm256_mul_pd(splat_d(2.0), _mm256_sub_pd(splat_d(1.0), normal_length)),
                                        _mm256_mul_pd(splat_d(kMomentError), length), _CMP_LE_OQ);
  const __m256d settled =
      _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(depth, zero, _CMP_GT_OQ), _mm256_cmp_pd(length, splat_d(kNoDirection), _CMP_GE_OQ)),
                    _mm256_and_pd(normals, _mm256_cmp_pd(error, allowed, _CMP_LE_OQ)));
  if ((_mm256_movemask_pd(settled) | (~_mm256_movemask_pd(present) & 0xF)) != 0xF) {
    return {false, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  const __m256d scale = _mm256_and_pd(present, _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(splat_d(k_world), n), depth), length));
  const __m256d fx = _mm256_mul_pd(scale, dx), fy = _mm256_mul_pd(scale, dy), fz = _mm256_mul_pd(scale, dz);
  const __m256d qx = _mm256_sub_pd(px, splat_d(centre.x())), qy = _mm256_sub_pd(py, splat_d(centre.y())),
                qz = _mm256_sub_pd(pz, splat_d(centre.z()));
  alignas(32) double out[6][4];
  _mm256_store_pd(out[0], fx);
  _mm256_store_pd(out[1], fy);
  _mm256_store_pd(out[2], fz);
  _mm256_store_pd(out[3], _mm256_sub_pd(_mm256_mul_pd(qy, fz), _mm256_mul_pd(qz, fy)));
  _mm256_store_pd(out[4], _mm256_sub_pd(_mm256_mul_pd(qz, fx), _mm256_mul_pd(qx, fz)));
  _mm256_store_pd(out[5], _mm256_sub_pd(_mm256_mul_pd(qx, fy), _mm256_mul_pd(qy, fx)));
  LeafMomentForce sum{true, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (std::size_t group = 0; group < tables::kLeafGroups; ++group) {  // in order, as the loop adds them
    sum.force += Eigen::Vector3d(out[0][group], out[1][group], out[2][group]);
    sum.torque += Eigen::Vector3d(out[3][group], out[4][group], out[5][group]);
  }
  return sum;
}
#endif

}  // namespace

LeafMomentForce leaf_moment_force(const geometry::ImplicitSurface& surface, const tables::LeafBlock& block,
                                  const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& centre, double k_world) {
  const Moments leaf{{block.centroid_mm[0], block.centroid_mm[1], block.centroid_mm[2]},
                     {block.mean_normal[0], block.mean_normal[1], block.mean_normal[2]},
                     block.radius_mm,
                     block.point_count};
  const LeafMomentForce whole = moment_force(surface, leaf, tip_mm, centre, k_world);
  if (whole.settled) {
    return whole;
  }
  // Too wide for the tool's curvature, or across an edge: each group of lanes settled from its
  // own moments (a quarter of the leaf's points, about half its radius), or the leaf is visited.
#if defined(__AVX2__)
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return group_moment_lanes<SurfaceKind::PlaneZ>(surface, block, tip_mm, centre, k_world);
    case SurfaceKind::Cylinder:
      return group_moment_lanes<SurfaceKind::Cylinder>(surface, block, tip_mm, centre, k_world);
    case SurfaceKind::Sphere:
      return group_moment_lanes<SurfaceKind::Sphere>(surface, block, tip_mm, centre, k_world);
    case SurfaceKind::Torus:
      return group_moment_lanes<SurfaceKind::Torus>(surface, block, tip_mm, centre, k_world);
  }
  return {false, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
#else
  LeafMomentForce sum{true, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (std::uint32_t group = 0; group < tables::kLeafGroups && group_count(block, group) > 0; ++group) {
    const Moments moments{{block.group_centroid_mm[0][group], block.group_centroid_mm[1][group], block.group_centroid_mm[2][group]},
                          {block.group_mean_normal[0][group], block.group_mean_normal[1][group], block.group_mean_normal[2][group]},
                          block.group_radius_mm[group],
                          group_count(block, group)};
    const LeafMomentForce part = moment_force(surface, moments, tip_mm, centre, k_world);
    if (!part.settled) {
      return part;
    }
    sum.force += part.force;
    sum.torque += part.torque;
  }
  return sum;
#endif
}

}  // namespace stencil::engine
