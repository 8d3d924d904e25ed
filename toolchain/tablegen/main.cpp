// stencil-tablegen: STL part + tool -> validated, checksummed stencil tables (.stbl); --inspect reads them back.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "firmware/services/report/installed_files.hpp"
#include "firmware/services/report/build_version.hpp"
#include "firmware/core/tables/table_format.hpp"
#include "toolchain/tablegen/file_io.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/inspect.hpp"
#include "toolchain/tablegen/rig_defaults.hpp"
#include "toolchain/tablegen/table_generator.hpp"
#include "toolchain/tablegen/table_writer.hpp"
#include "toolchain/tablegen/tool_option.hpp"

namespace {

using namespace stencil::tablegen;
using Clock = std::chrono::steady_clock;

// A progress line on a terminal, shown only for work that has taken more than a second.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO) != 0), start_(Clock::now()) {}
  ~Progress() { finish(); }

  void operator()(const char* phase, double fraction) {
    if (!enabled_) {
      return;
    }
    const auto now = Clock::now();
    if (now - start_ < std::chrono::seconds(1) || now - last_ < std::chrono::milliseconds(100)) {
      return;
    }
    last_ = now;
    std::fprintf(stderr, "\rstencil-tablegen: %-14s %5.1f%%", phase, 100.0 * fraction);
    shown_ = true;
  }

  void finish() {
    if (shown_) {
      std::fprintf(stderr, "\r%-48s\r", "");
      shown_ = false;
    }
  }

 private:
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_;
  Clock::time_point last_{};
};

std::string megabytes(std::size_t bytes) {
  std::ostringstream text;
  text.precision(3);
  text << static_cast<double>(bytes) / 1e6 << " MB";
  return text.str();
}

std::string table_symbol(const std::string& output) {
  std::string name = "stencil_table_" + std::filesystem::path(output).stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) {
      c = '_';
    }
  }
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "stencil-tablegen: turns an STL part and a tool into the stencil tables the controller loads (.stbl):\n"
      "a point cloud covering the part's surface with normals, a 14-DOP tree over it, the tool's BSP, the\n"
      "mesh for display, reachability by a vertical tool, and a CRC-32. Millimetres throughout.\n"
      "Exit status: 0 done, 2 bad input or options (nothing written), 1 anything else."};
  app.get_formatter()->column_width(34);
  app.set_version_flag("--version", stencil::report::version_text("stencil-tablegen"));

  std::string part_path;
  std::string output_path;
  std::string tool_text;
  std::string holder_text;
  std::optional<double> spacing;
  GeneratorOptions options;
  // The rig's, from the board this program is linked with.
  const RigDefaults rig = rig_defaults();
  options.rig_largest_backlash_mm = rig.largest_backlash_mm;
  std::string units = "mm";
  std::string place = "as-is";
  std::vector<double> workspace(rig.workspace_mm.begin(), rig.workspace_mm.end());
  std::string emit_directory;
  std::string inspect_path;
  bool json = false;
  bool quiet = false;
  options.threads = std::max(1u, std::thread::hardware_concurrency());

  app.add_option("part", part_path,
                 "the part: an ASCII or binary STL file, or sample:NAME for a shipped sample part (hex_prism, "
                 "slotted_block, thin_fin: share/stencil/parts beside an installed program, else the build's parts/)");
  app.add_option("-o,--output", output_path, "the table to write (default: the part's name with .stbl, here)");
  app.add_option("--tool", tool_text,
                 "flat:d=D[,l=L] | ball:d=D[,l=L] | bull:d=D,r=RC[,l=L] (mm; flute length L defaults to 4*D)");
  app.add_option("--holder", holder_text, "shank/holder above the flutes, d=D,l=L (default d=10,l=20)");
  app.add_option("--spacing", spacing,
                 "covering radius h (mm): no surface point is farther than h from a sample; refused when its "
                 "gouge bound exceeds --max-gouge, unless --force");
  app.add_option("--max-gouge", options.max_gouge_mm,
                 "the deepest the tool may dip between samples (mm); chooses h when --spacing is not given")
      ->capture_default_str();
  app.add_option("--extra-points", options.extra_points, "add N seeded area-weighted random points")
      ->capture_default_str();
  app.add_option("--seed", options.seed, "seed for --extra-points")->capture_default_str();
  app.add_option("--units", units, "STL units: mm or in (inches are converted to mm)")
      ->check(CLI::IsMember({"mm", "in"}))
      ->capture_default_str();
  app.add_option("--scale", options.placement.scale, "multiply every coordinate by S, after --units")
      ->capture_default_str();
  app.add_option("--place", place,
                 "as-is: use the coordinates; center: centre in x and y, lowest point on the floor (z = 0)")
      ->check(CLI::IsMember({"as-is", "center"}))
      ->capture_default_str();
  app.add_option("--workspace", workspace, "the machine workspace X,Y,Z (mm): the part must fit [0,X]x[0,Y]x[0,Z]")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str();
  app.add_option("--allowance", options.allowance_mm,
                 "inflate the stencil by a finishing allowance (mm); warns below the rig's largest backlash")
      ->capture_default_str();
  app.add_flag("--flip", options.placement.flip, "reverse every facet (for a mesh whose normals point inward)");
  app.add_option("--emit-cpp", emit_directory, "also write the table as C++ (a constant array) into DIR");
  app.add_option("--threads", options.threads, "worker threads (the output is the same for any count)")
      ->capture_default_str();
  app.add_flag("--quiet", quiet, "no progress and no summary line (warnings and errors still go to stderr)");
  app.add_flag("--force", options.force, "accept a --spacing whose gouge bound exceeds --max-gouge");
  app.add_option("--inspect", inspect_path, "validate a table with the controller's loader and describe it");
  app.add_flag("--json", json, "with --inspect: the description as JSON");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::CallForVersion&) {
    std::cout << stencil::report::version_text("stencil-tablegen") << "\n";
    return 0;
  } catch (const CLI::ParseError& error) {
    std::cerr << "stencil-tablegen: " << error.what() << "\n(run stencil-tablegen --help for the options)\n";
    return 2;
  }

  if (!inspect_path.empty()) {
    if (!part_path.empty() || !tool_text.empty()) {
      std::cerr << "stencil-tablegen: --inspect takes only a table (and --json), not a part or a tool\n";
      return 2;
    }
    return inspect_table(inspect_path, json, std::cout, std::cerr);
  }
  if (json) {
    std::cerr << "stencil-tablegen: --json goes with --inspect\n";
    return 2;
  }
  if (part_path.empty() || tool_text.empty()) {
    std::cerr << "stencil-tablegen: expected a part and --tool, e.g. stencil-tablegen part.stl -o part.stbl "
                 "--tool ball:d=3\n(run stencil-tablegen --help for the options)\n";
    return 2;
  }
  {
    std::string error;
    part_path = stencil::report::resolve_sample_part(part_path, error);  // sample:NAME, from what ships
    if (part_path.empty()) {
      std::cerr << "stencil-tablegen: " << error << "\n";
      return 2;
    }
  }
  if (output_path.empty()) {
    output_path = std::filesystem::path(part_path).stem().string() + ".stbl";
  }

  const auto started = Clock::now();
  try {
    options.tool = parse_tool(tool_text, holder_text);
    if (spacing) {
      options.spacing_mm = *spacing;
    }
    options.placement.millimetres_per_unit = units == "in" ? 25.4 : 1.0;
    options.placement.placement = place == "center" ? Placement::Center : Placement::AsIs;
    options.placement.workspace_mm = {workspace[0], workspace[1], workspace[2]};
    check_options(options);
    if (!emit_directory.empty() && !std::filesystem::is_directory(emit_directory)) {
      throw InputError("--emit-cpp " + emit_directory + ": not a directory");
    }

    const std::vector<std::byte> stl_bytes = read_file_bytes(part_path);
    // Outputs are opened before the work, so an unwritable place is refused at once; they appear
    // only when everything has succeeded.
    PendingFile table_file(output_path);
    std::optional<PendingFile> cpp_file;
    const std::string symbol = table_symbol(output_path);
    if (!emit_directory.empty()) {
      cpp_file.emplace(emit_directory + "/" + symbol + ".cpp");
    }
    GeneratorReport report;
    Progress progress(!quiet);
    TableContents contents = generate_tables(stl_bytes, part_path, options, report,
                                             [&](const char* phase, double fraction) { progress(phase, fraction); });
    progress.finish();
    for (const std::string& warning : report.warnings) {
      std::cerr << "stencil-tablegen: warning: " << warning << "\n";
    }
    const TableBytes bytes = assemble_table(contents);
    table_file.write(bytes.data(), bytes.size());
    if (cpp_file) {
      const std::string source = table_as_cpp(symbol, bytes);
      cpp_file->write(source.data(), source.size());
      cpp_file->commit();
    }
    try {
      table_file.commit();
    } catch (const InputError&) {
      if (cpp_file) {
        std::filesystem::remove(cpp_file->path());  // all or nothing: no C++ without its table
      }
      throw;
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
    if (!quiet) {
      std::printf(
          "%s -> %s: %zu triangles, %zu points, covering radius %.4f mm (gouge <= %.4f mm), %zu nodes, %s, "
          "reachable %zu points / %zu triangles, %u threads, %.2f s\n",
          part_path.c_str(), output_path.c_str(), contents.triangles.size(), contents.points.size(),
          report.covering_radius_mm, report.gouge_bound_mm, contents.nodes.size(), megabytes(bytes.size()).c_str(),
          report.reachable_points, report.reachable_triangles, options.threads, seconds);
    }
    return 0;
  } catch (const InputError& error) {
    std::cerr << "stencil-tablegen: " << error.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "stencil-tablegen: out of memory\n";
    return 1;
  }
}
