// The .stbl table file: byte layout of the header and of every section, shared by the table
// generator (writer) and the firmware loader (reader). A layout change breaks the build here.
//
// File layout (all integers and floats little-endian, IEEE-754):
//   [0, 512)        TableHeader
//   sections        each at an offset that is a multiple of 64, in the order of TableSection,
//                   with zero bytes between them; the header's section table gives offset and size.
//     Tool          ToolSection: the tool's BSP tree as built from the header's tool spec
//     Points        PackedPoint[point_count]: world millimetres, in BVH leaf order
//     Leaves        LeafBlock[leaf_count]: each leaf's points and their unit outward normals (of
//                   each point's triangle) as float lanes, with a sphere bounding the points
//     TriangleIds   uint32[point_count]: the triangle each point lies on
//     PointFlags    uint8[point_count]: kPointReachable
//     Triangles     PackedTriangle[triangle_count]: the part's mesh for display (world mm)
//     TriangleFlags uint8[triangle_count]: kTriangleReachable
//     Nodes         BvhNode[node_count]: binary 14-DOP tree over the points, depth-first
//   crc32 (zlib's CRC-32) covers every byte from offset 20 (just after the crc32 field) to the end.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>

namespace stencil::tables {

static_assert(std::endian::native == std::endian::little, "tables are read in place: little-endian hosts only");

inline constexpr std::uint8_t kTableMagic[8] = {'S', 'T', 'E', 'N', 'C', 'I', 'L', 'T'};
// 2: the packed leaves (LeafBlock) replace version 1's per-point normals.
// 3: leaves of up to 64 points (LeafBlock of 1600 bytes): half the nodes to walk and half the
// leaves to classify for the same points (deep-corner query at 1e6 points: 387,939 instructions
// against 483,828 with 32). The loader refuses older tables by name, with "regenerate with
// stencil-tablegen".
// 4: each leaf's block also holds its points' centroid and their normals' mean (LeafMoments), so
// the query settles a leaf wholly deeper than the tolerance without visiting its points.
// 5: the same for each group of 16 lanes (LeafGroupMoments, the generator ordering a leaf's points
// so each group is compact): a leaf too wide against the tool's curvature for its own moments is
// settled from its groups' (deep-corner query at 1e6 points: 281,069 instructions against 300,592),
// and a group that cannot penetrate is skipped in a leaf that is visited.
inline constexpr std::uint32_t kTableFormatVersion = 5;
inline constexpr std::size_t kSectionAlignment = 64;
inline constexpr std::size_t kCrcStartOffset = 20;

// Capacities the controller reserves for (static storage), and the most the generator writes.
inline constexpr std::uint32_t kMaxTablePoints = 4'194'304;     // 2^22
inline constexpr std::uint32_t kMaxTableTriangles = 2'097'152;  // 2^21
// The generator's tree has full leaves of kMaxLeafPoints points but the last, so fewer than
// 2 * points / 64 + 1 nodes; a table may hold smaller leaves, up to this many nodes.
inline constexpr std::uint32_t kMaxTableNodes = kMaxTablePoints / 4;
inline constexpr std::uint32_t kMaxLeafPoints = 64;
// The loader walks the tree with a fixed stack: deeper trees are refused. A median split of
// kMaxTablePoints points is 18 levels deep.
inline constexpr std::uint32_t kMaxTreeDepth = 64;

enum class TableSection : std::uint32_t {
  Tool = 0,
  Points,
  Leaves,
  TriangleIds,
  PointFlags,
  Triangles,
  TriangleFlags,
  Nodes,
  Count,
};
inline constexpr std::size_t kSectionCount = static_cast<std::size_t>(TableSection::Count);

inline constexpr std::uint8_t kPointReachable = 1u << 0;     // a vertical tool can touch it legally
inline constexpr std::uint8_t kTriangleReachable = 1u << 0;  // at least one of its points is reachable

struct SectionEntry {
  std::uint64_t offset;  // from the start of the file; a multiple of kSectionAlignment
  std::uint64_t bytes;   // exactly count * element size
};
static_assert(sizeof(SectionEntry) == 16);

struct TableHeader {
  std::uint8_t magic[8];            // kTableMagic
  std::uint32_t format_version;     // kTableFormatVersion
  std::uint32_t header_bytes;       // sizeof(TableHeader)
  std::uint32_t crc32;              // CRC-32 of bytes [kCrcStartOffset, file_bytes)
  std::uint32_t flags;              // reserved, 0
  std::uint64_t file_bytes;         // size of the whole file
  std::uint32_t triangle_count;
  std::uint32_t point_count;
  std::uint32_t node_count;
  std::uint32_t vertex_point_count;  // how many of the points are mesh vertices (the rest: centroids, samples)
  SectionEntry sections[kSectionCount];
  double covering_radius_mm;         // achieved: every surface point is within this of a sample
  double requested_spacing_mm;       // h asked for (directly or from --max-gouge)
  double gouge_bound_mm;             // deepest the tool can dip between samples at the achieved spacing
  double allowance_mm;               // stencil inflated by this finishing allowance
  double part_min_mm[3];             // bounds of the points, world frame
  double part_max_mm[3];
  double workspace_mm[3];            // the box [0,X]x[0,Y]x[0,Z] the part was placed in
  double stl_to_world_scale;         // world mm per STL unit (units times --scale)
  std::uint64_t seed;                // --seed for the extra random points
  std::uint64_t extra_points;        // --extra-points
  std::uint32_t tool_kind;           // geometry::CutterKind
  std::uint32_t leaf_count;         // the tree's leaves: one LeafBlock each
  double tool_diameter_mm;
  double tool_flute_length_mm;
  double tool_corner_radius_mm;
  double tool_holder_diameter_mm;
  double tool_holder_length_mm;
  std::uint8_t source_sha256[32];    // SHA-256 of the source STL file
  std::uint64_t source_bytes;        // size of the source STL file
  std::uint32_t source_triangle_count;     // triangles read from the STL
  std::uint32_t dropped_degenerate_count;  // zero-area triangles dropped
  std::uint32_t reachable_point_count;
  std::uint32_t reachable_triangle_count;
  std::uint8_t reserved[104];
};
static_assert(sizeof(TableHeader) == 512, "the header is 512 bytes");
static_assert(offsetof(TableHeader, crc32) == 16 && offsetof(TableHeader, flags) == kCrcStartOffset);
static_assert(offsetof(TableHeader, sections) == 48);
static_assert(offsetof(TableHeader, covering_radius_mm) == 176);
static_assert(offsetof(TableHeader, tool_kind) == 304);
static_assert(offsetof(TableHeader, source_sha256) == 352);
static_assert(offsetof(TableHeader, reserved) == 408);

struct PackedPoint {
  float x_mm;
  float y_mm;
  float z_mm;
};
static_assert(sizeof(PackedPoint) == 12);

struct PackedTriangle {
  PackedPoint vertices[3];  // counter-clockwise seen from outside (right-hand rule gives the outward normal)
};
static_assert(sizeof(PackedTriangle) == 36);

// One node of the points' tree. Internal nodes (point_count == 0) have their left child right
// after them and their right child at right_child; leaves hold points [first_point, first_point + point_count).
struct BvhNode {
  double dop_min[7];  // geometry::Kdop14 of everything below, slab order of kKdopSlabDirections
  double dop_max[7];
  std::uint32_t first_point;
  std::uint32_t point_count;
  std::uint32_t right_child;
  std::uint32_t leaf;  // a leaf's LeafBlock (leaves numbered in depth-first order); 0 for an internal node
};
static_assert(sizeof(BvhNode) == 128);
static_assert(offsetof(BvhNode, first_point) == 112);

// One leaf of the points' tree packed for the query's lanes: its points and their normals as
// float lanes, ready for vector loads without gathering (the block and each array are 64- and
// 32-byte aligned in the file), lanes past point_count repeating the last point, so every lane
// holds a real point. The points are the very floats of the Points section, so a verdict taken
// in double precision from a lane is the one taken from the point. The sphere bounds every point of
// the leaf in double precision (checked by the loader): the query bounds the depth of every point
// of the leaf from the depth of its centre, and settles a leaf that lies wholly deeper than the
// tolerance from its moments (tables/leaf_moments.hpp) without visiting its points, or from its
// groups' moments: lanes 16g to 16g + 15 (those below point_count) are group g, the generator
// ordering the leaf's points so that each group lies close together.
inline constexpr std::uint32_t kLeafGroupPoints = 16;
inline constexpr std::uint32_t kLeafGroups = kMaxLeafPoints / kLeafGroupPoints;
static_assert(kMaxLeafPoints % kLeafGroupPoints == 0);
struct LeafGroupMoments {
  float centroid_mm[3];  // of the group's points; all zero for a group past point_count
  float mean_normal[3];
  float radius_mm;       // every point of the group within it of the centroid (in double precision)
};

struct LeafBlock {
  float x_mm[kMaxLeafPoints];
  float y_mm[kMaxLeafPoints];
  float z_mm[kMaxLeafPoints];
  float nx[kMaxLeafPoints];  // unit outward normal of each point's triangle
  float ny[kMaxLeafPoints];
  float nz[kMaxLeafPoints];
  std::uint32_t first_point;  // the leaf's node's first_point and point_count
  std::uint32_t point_count;
  float centre_mm[3];         // every point within radius_mm of it (in double precision)
  float radius_mm;
  float centroid_mm[3];       // tables::leaf_moments of the block, bit for bit (the loader checks)
  float mean_normal[3];
  // Likewise each group's (LeafMoments::groups), component by component so that the query reads
  // the four groups' x (or y, ...) with one load: group g's centroid is group_centroid_mm[0..2][g].
  float group_centroid_mm[3][kLeafGroups];
  float group_mean_normal[3][kLeafGroups];
  float group_radius_mm[kLeafGroups];
  std::uint8_t reserved[32];
};
static_assert(sizeof(LeafBlock) == 1728 && sizeof(LeafBlock) % 64 == 0, "blocks stay 64-byte aligned in the file");
static_assert(offsetof(LeafBlock, nx) == 768 && offsetof(LeafBlock, first_point) == 1536);
static_assert(offsetof(LeafBlock, centroid_mm) == 1560 && offsetof(LeafBlock, group_centroid_mm) == 1584 &&
              offsetof(LeafBlock, reserved) == 1696);

// The tool's BSP tree in the file: the fields of geometry::ToolBsp, each byte defined.
struct ToolSectionSurface {
  std::uint8_t kind;        // geometry::SurfaceKind
  std::int8_t solid_side;   // geometry::SolidSide
  std::uint8_t reserved[6];
  double center_r_mm;
  double center_z_mm;
  double radius_mm;
};
static_assert(sizeof(ToolSectionSurface) == 32);

struct ToolSectionNode {
  std::uint8_t test;  // geometry::NodeTest
  std::uint8_t surface_a;
  std::uint8_t surface_b;
  std::uint8_t when_true_kind;  // geometry::BspLink::Kind
  std::uint8_t when_true_index;
  std::uint8_t when_false_kind;
  std::uint8_t when_false_index;
  std::uint8_t reserved;
};
static_assert(sizeof(ToolSectionNode) == 8);

struct ToolSectionRegion {
  std::uint8_t surface;
  std::uint8_t face;  // geometry::ToolFace
  std::uint8_t reserved[2];
};
static_assert(sizeof(ToolSectionRegion) == 4);

struct ToolSection {
  std::uint32_t surface_count;
  std::uint32_t node_count;
  std::uint32_t region_count;
  std::uint32_t reserved;
  ToolSectionSurface surfaces[16];
  ToolSectionNode nodes[32];
  ToolSectionRegion regions[8];
};
static_assert(sizeof(ToolSection) == 16 + 16 * 32 + 32 * 8 + 8 * 4);

}  // namespace stencil::tables
