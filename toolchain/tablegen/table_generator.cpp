// The generation pipeline: parse, place, sample, tree, reachability, pack.
#include "toolchain/tablegen/table_generator.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

#include <nettle/sha2.h>

#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/tables/tool_section.hpp"
#include "toolchain/tablegen/bvh_builder.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/point_cloud.hpp"
#include "toolchain/tablegen/reachability.hpp"
#include "toolchain/tablegen/stl_reader.hpp"

namespace stencil::tablegen {
namespace {

std::string number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

void require_positive(double value, const char* option) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InputError(std::string(option) + " " + number(value) + ": expected a finite number greater than 0");
  }
}

tables::PackedPoint pack(const Eigen::Vector3d& point) {
  return {static_cast<float>(point.x()), static_cast<float>(point.y()), static_cast<float>(point.z())};
}

void collect_warnings(const std::string& file_name, const GeneratorOptions& options, const MeshReport& mesh,
                      std::vector<std::string>& warnings) {
  if (mesh.solid_count > 1) {
    warnings.push_back(file_name + ": " + std::to_string(mesh.solid_count) +
                       " 'solid' blocks; all of them were read as one part");
  }
  if (mesh.degenerate_dropped > 0) {
    warnings.push_back(file_name + ": dropped " + std::to_string(mesh.degenerate_dropped) +
                       " degenerate (zero-area) facets");
  }
  if (mesh.normal_disagreements > 0) {
    warnings.push_back(file_name + ": " + std::to_string(mesh.normal_disagreements) +
                       " facet normals differ by more than 10 degrees from their vertices' winding; "
                       "normals were recomputed from the vertices (right-hand rule)");
  }
  if (mesh.open_edges > 0) {
    warnings.push_back(file_name + ": " + std::to_string(mesh.open_edges) +
                       " open edges: the mesh is not closed (the stencil still works on it)");
  }
  if (mesh.non_manifold_edges > 0) {
    warnings.push_back(file_name + ": " + std::to_string(mesh.non_manifold_edges) +
                       " non-manifold edges (shared by more than two facets)");
  }
  if (mesh.inconsistent_edges > 0) {
    warnings.push_back(file_name + ": " + std::to_string(mesh.inconsistent_edges) +
                       " edges where neighbouring facets are oriented inconsistently");
  }
  if (mesh.signed_volume_mm3 < 0.0) {
    warnings.push_back(file_name + ": the facet normals mostly point inward (signed volume " +
                       number(mesh.signed_volume_mm3) + " mm^3)" +
                       (options.placement.flip ? "" : "; use --flip to turn them outward"));
  }
  const double backlash = options.rig_largest_backlash_mm;
  if (options.allowance_mm < backlash) {
    warnings.push_back("allowance " + number(options.allowance_mm) + " mm is smaller than the rig's largest backlash (" +
                       number(backlash) +
                       " mm): a climb cut can pull the table through the backlash and into the part");
  }
}

}  // namespace

void check_options(const GeneratorOptions& options) {
  geometry::ToolBsp scratch;
  const geometry::ToolBuildResult built = geometry::build_tool_bsp(options.tool, scratch);
  if (!built.ok) {
    throw InputError("--tool/--holder: " + std::string(built.field) + " " + number(built.value) + ": expected " +
                     built.expected);
  }
  require_positive(options.max_gouge_mm, "--max-gouge");
  if (options.spacing_mm) {
    require_positive(*options.spacing_mm, "--spacing");
  }
  require_positive(options.placement.scale, "--scale");
  for (int axis = 0; axis < 3; ++axis) {
    require_positive(options.placement.workspace_mm[axis], "--workspace");
  }
  if (!std::isfinite(options.allowance_mm) || options.allowance_mm < 0.0) {
    throw InputError("--allowance " + number(options.allowance_mm) + ": expected a finite number, 0 or more");
  }
  if (options.extra_points > tables::kMaxTablePoints) {
    throw InputError("--extra-points " + std::to_string(options.extra_points) + ": expected at most " +
                     std::to_string(tables::kMaxTablePoints) + " (the controller's point capacity)");
  }
  if (options.threads == 0) {
    throw InputError("--threads 0: expected at least 1");
  }
  if (options.spacing_mm && !options.force) {
    const double bound = gouge_bound_mm(options.tool, *options.spacing_mm);
    if (bound > options.max_gouge_mm) {
      throw InputError("--spacing " + number(*options.spacing_mm) + " mm lets the tool dip up to " + number(bound) +
                       " mm between samples, more than --max-gouge " + number(options.max_gouge_mm) +
                       " mm; use a smaller --spacing, a larger --max-gouge, or --force");
    }
  }
}

TableContents generate_tables(std::span<const std::byte> stl_bytes, const std::string& file_name,
                              const GeneratorOptions& options, GeneratorReport& report, const ProgressSink& progress) {
  check_options(options);
  progress("reading STL", 0.0);
  const StlMesh stl = parse_stl(stl_bytes, file_name);
  if (stl.triangles.size() > tables::kMaxTableTriangles) {
    throw InputError(file_name + ": " + std::to_string(stl.triangles.size()) +
                     " triangles, more than the controller's capacity of " +
                     std::to_string(tables::kMaxTableTriangles) + "; simplify the mesh");
  }
  progress("checking mesh", 0.0);
  const PartMesh mesh = prepare_part(stl, options.placement, file_name);
  report.mesh = mesh.report;
  collect_warnings(file_name, options, mesh.report, report.warnings);

  CloudOptions cloud_options;
  cloud_options.covering_radius_mm =
      options.spacing_mm ? *options.spacing_mm : covering_radius_for_gouge(options.tool, options.max_gouge_mm);
  cloud_options.extra_points = options.extra_points;
  cloud_options.seed = options.seed;
  cloud_options.allowance_mm = options.allowance_mm;
  cloud_options.threads = options.threads;
  const std::uint64_t needed = count_cloud_points(mesh, cloud_options);
  if (needed > tables::kMaxTablePoints) {
    throw InputError(file_name + ": covering the surface to " + number(cloud_options.covering_radius_mm) +
                     " mm needs " + std::to_string(needed) + " points, more than the controller's capacity of " +
                     std::to_string(tables::kMaxTablePoints) +
                     "; allow a larger gouge (--max-gouge), or set --spacing (with --force)");
  }
  const PointCloud cloud =
      build_point_cloud(mesh, cloud_options, [&](double fraction) { progress("sampling", fraction); });

  TableContents contents{};
  std::vector<tables::PackedPoint> packed(cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    packed[i] = pack(cloud.points[i].position_mm);
  }
  progress("tree", 0.0);
  PointTree tree = build_point_tree(packed, options.threads);
  progress("tree", 1.0);
  contents.nodes = std::move(tree.nodes);
  contents.points.resize(packed.size());
  contents.normals.resize(packed.size());
  contents.triangle_ids.resize(packed.size());
  for (std::size_t slot = 0; slot < packed.size(); ++slot) {
    const CloudPoint& point = cloud.points[tree.order[slot]];
    contents.points[slot] = packed[tree.order[slot]];
    contents.normals[slot] = pack(point.normal);
    contents.triangle_ids[slot] = point.triangle;
  }

  const geometry::ToolBuildResult built = geometry::build_tool_bsp(options.tool, contents.tool);
  static_cast<void>(built);  // checked in check_options
  const ReachInput reach{contents.points, contents.normals, contents.nodes, contents.tool, options.placement.workspace_mm};
  contents.point_flags =
      mark_reachable(reach, options.threads, [&](double fraction) { progress("reachability", fraction); });

  contents.triangles.resize(mesh.triangles.size());
  contents.triangle_flags.assign(mesh.triangles.size(), 0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (std::size_t v = 0; v < 3; ++v) {
      contents.triangles[t].vertices[v] = pack(mesh.triangles[t].vertices[v]);
    }
  }
  for (std::size_t i = 0; i < contents.point_flags.size(); ++i) {
    if (contents.point_flags[i] & tables::kPointReachable) {
      ++report.reachable_points;
      contents.triangle_flags[contents.triangle_ids[i]] = tables::kTriangleReachable;
    }
  }
  for (const std::uint8_t flags : contents.triangle_flags) {
    report.reachable_triangles += flags != 0 ? 1 : 0;
  }
  report.covering_radius_mm = cloud.achieved_covering_radius_mm;
  report.gouge_bound_mm = gouge_bound_mm(options.tool, cloud.achieved_covering_radius_mm);

  tables::TableHeader& header = contents.header;
  std::memset(&header, 0, sizeof(header));
  header.vertex_point_count = static_cast<std::uint32_t>(cloud.vertex_points);
  header.covering_radius_mm = report.covering_radius_mm;
  header.requested_spacing_mm = cloud_options.covering_radius_mm;
  header.gouge_bound_mm = report.gouge_bound_mm;
  header.allowance_mm = options.allowance_mm;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const tables::PackedPoint& point : contents.points) {
    const Eigen::Vector3d p(point.x_mm, point.y_mm, point.z_mm);
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  for (int axis = 0; axis < 3; ++axis) {
    header.part_min_mm[axis] = low[axis];
    header.part_max_mm[axis] = high[axis];
    header.workspace_mm[axis] = options.placement.workspace_mm[axis];
  }
  header.stl_to_world_scale = options.placement.millimetres_per_unit * options.placement.scale;
  header.seed = options.seed;
  header.extra_points = options.extra_points;
  tables::store_tool_spec(options.tool, header);
  sha256_ctx sha;
  sha256_init(&sha);
  sha256_update(&sha, stl_bytes.size(), reinterpret_cast<const std::uint8_t*>(stl_bytes.data()));
  sha256_digest(&sha, sizeof(header.source_sha256), header.source_sha256);
  header.source_bytes = stl_bytes.size();
  header.source_triangle_count = static_cast<std::uint32_t>(stl.triangles.size());
  header.dropped_degenerate_count = static_cast<std::uint32_t>(mesh.report.degenerate_dropped);
  header.reachable_point_count = static_cast<std::uint32_t>(report.reachable_points);
  header.reachable_triangle_count = static_cast<std::uint32_t>(report.reachable_triangles);
  return contents;
}

}  // namespace stencil::tablegen
