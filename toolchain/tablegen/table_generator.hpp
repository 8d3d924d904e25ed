// The whole generation: STL bytes and options in, table contents and a report out (no I/O).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "firmware/core/geometry/tool_spec.hpp"
#include "toolchain/tablegen/part_mesh.hpp"
#include "toolchain/tablegen/table_writer.hpp"

namespace stencil::tablegen {

inline constexpr double kDefaultMaxGouge_mm = 0.004;

struct GeneratorOptions {
  geometry::ToolSpec tool;
  std::optional<double> spacing_mm;  // --spacing h; otherwise h comes from max_gouge_mm
  double max_gouge_mm = kDefaultMaxGouge_mm;
  bool force = false;                // accept a --spacing whose gouge bound exceeds --max-gouge
  std::uint64_t extra_points = 0;
  std::uint64_t seed = 1;
  PlacementOptions placement;
  double allowance_mm = 0.0;
  // The largest backlash of the rig the tables are for (the caller's: the program's is the rig's,
  // rig_defaults.hpp): an allowance below it is warned about. 0: no rig, no warning.
  double rig_largest_backlash_mm = 0.0;
  unsigned threads = 1;
};

// What happened, for the summary line and the warnings.
struct GeneratorReport {
  MeshReport mesh;
  std::vector<std::string> warnings;
  double covering_radius_mm = 0.0;
  double gouge_bound_mm = 0.0;
  std::size_t reachable_points = 0;
  std::size_t reachable_triangles = 0;
};

// Progress of a named phase, fraction in [0, 1]. Called from the generating thread only.
using ProgressSink = std::function<void(const char* phase, double fraction)>;

// Reads nothing and writes nothing: parses `stl_bytes` (named `file_name` in messages), builds the
// tables and returns them with the report. Throws InputError for bad input or options.
[[nodiscard]] TableContents generate_tables(std::span<const std::byte> stl_bytes, const std::string& file_name,
                                            const GeneratorOptions& options, GeneratorReport& report,
                                            const ProgressSink& progress);

// Checks the options on their own (before any file is read); throws InputError naming the option.
void check_options(const GeneratorOptions& options);

}  // namespace stencil::tablegen
