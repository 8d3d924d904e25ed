// Table inspection for people (a summary) and machines (--json).
#include "toolchain/tablegen/inspect.hpp"

#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "firmware/core/tables/table_loader.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/table_writer.hpp"

namespace stencil::tablegen {
namespace {

const char* kind_name(std::uint32_t kind) {
  switch (kind) {
    case 0:
      return "flat";
    case 1:
      return "ball";
    case 2:
      return "bull";
  }
  return "unknown";
}

std::string hex(const std::uint8_t* bytes, std::size_t count) {
  std::ostringstream text;
  for (std::size_t i = 0; i < count; ++i) {
    text << std::hex << std::setw(2) << std::setfill('0') << static_cast<unsigned>(bytes[i]);
  }
  return text.str();
}

// Whole numbers (sizes, counts, CRCs) exactly; others with every digit that matters.
std::string exact(double value) {
  std::ostringstream text;
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) < 9.007199254740992e15) {
    text << static_cast<long long>(value);
  } else {
    text << std::setprecision(17) << value;
  }
  return text.str();
}

}  // namespace

int inspect_table(const std::string& path, bool json, std::ostream& out, std::ostream& err) {
  TableBytes bytes;
  try {
    bytes = read_table_file(path);
  } catch (const InputError& error) {
    err << "stencil-tablegen: " << error.what() << "\n";
    return 2;
  }
  tables::PartTables part{};
  const tables::TableLoadResult result = tables::load_tables({bytes.data(), bytes.size()}, part);
  if (!result.ok && result.expected == tables::kOlderVersion) {
    err << "stencil-tablegen: " << path << ": format version " << exact(result.value)
        << ": regenerate with stencil-tablegen (this build reads format version " << tables::kTableFormatVersion << ")\n";
    return 2;
  }
  if (!result.ok) {
    err << "stencil-tablegen: " << path << ": " << result.field << " (at " << result.index << "): expected "
        << result.expected << "; found " << exact(result.value) << "\n";
    return 2;
  }
  const tables::TableHeader& header = part.header;
  if (json) {
    nlohmann::json summary = {
        {"file", path},
        {"bytes", header.file_bytes},
        {"format_version", header.format_version},
        {"crc32", header.crc32},
        {"triangles", header.triangle_count},
        {"points", header.point_count},
        {"vertex_points", header.vertex_point_count},
        {"nodes", header.node_count},
        {"leaves", header.leaf_count},
        {"covering_radius_mm", header.covering_radius_mm},
        {"requested_spacing_mm", header.requested_spacing_mm},
        {"gouge_bound_mm", header.gouge_bound_mm},
        {"allowance_mm", header.allowance_mm},
        {"part_min_mm", {header.part_min_mm[0], header.part_min_mm[1], header.part_min_mm[2]}},
        {"part_max_mm", {header.part_max_mm[0], header.part_max_mm[1], header.part_max_mm[2]}},
        {"workspace_mm", {header.workspace_mm[0], header.workspace_mm[1], header.workspace_mm[2]}},
        {"stl_to_world_scale", header.stl_to_world_scale},
        {"seed", header.seed},
        {"extra_points", header.extra_points},
        {"tool",
         {{"kind", kind_name(header.tool_kind)},
          {"diameter_mm", header.tool_diameter_mm},
          {"flute_length_mm", header.tool_flute_length_mm},
          {"corner_radius_mm", header.tool_corner_radius_mm},
          {"holder_diameter_mm", header.tool_holder_diameter_mm},
          {"holder_length_mm", header.tool_holder_length_mm}}},
        {"source", {{"sha256", hex(header.source_sha256, 32)}, {"bytes", header.source_bytes},
                    {"triangles", header.source_triangle_count}, {"degenerate_dropped", header.dropped_degenerate_count}}},
        {"reachable_points", header.reachable_point_count},
        {"reachable_triangles", header.reachable_triangle_count},
    };
    out << summary.dump(2) << "\n";
    return 0;
  }
  out << path << ": valid stencil table, format " << header.format_version << ", " << header.file_bytes
      << " bytes, CRC-32 " << std::hex << std::setw(8) << std::setfill('0') << header.crc32 << std::dec << "\n"
      << "  tool       " << kind_name(header.tool_kind) << " d=" << header.tool_diameter_mm
      << " l=" << header.tool_flute_length_mm;
  if (header.tool_kind == 2) {
    out << " r=" << header.tool_corner_radius_mm;
  }
  out << ", holder d=" << header.tool_holder_diameter_mm << " l=" << header.tool_holder_length_mm << " (mm)\n"
      << "  part       " << header.triangle_count << " triangles, bounds [" << header.part_min_mm[0] << ", "
      << header.part_max_mm[0] << "] x [" << header.part_min_mm[1] << ", " << header.part_max_mm[1] << "] x ["
      << header.part_min_mm[2] << ", " << header.part_max_mm[2] << "] mm in workspace " << header.workspace_mm[0]
      << " x " << header.workspace_mm[1] << " x " << header.workspace_mm[2] << " mm\n"
      << "  points     " << header.point_count << " (" << header.vertex_point_count << " vertices), covering radius "
      << header.covering_radius_mm << " mm (asked " << header.requested_spacing_mm << "), undetectable gouge <= "
      << header.gouge_bound_mm << " mm, allowance " << header.allowance_mm << " mm\n"
      << "  reachable  " << header.reachable_point_count << " points, " << header.reachable_triangle_count
      << " triangles (3-axis, tool vertical)\n"
      << "  tree       " << header.node_count << " nodes, " << header.leaf_count << " leaves\n"
      << "  source     " << header.source_bytes << " bytes, " << header.source_triangle_count << " facets ("
      << header.dropped_degenerate_count << " degenerate dropped), sha256 " << hex(header.source_sha256, 32) << "\n";
  return 0;
}

}  // namespace stencil::tablegen
