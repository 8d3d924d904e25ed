// stencil-bench: time of the collision query and of the full cycle (query + remediation with its
// sweep) on finely tessellated parts of 1e4, 1e5 and 1e6 points, in free space, in light and deep
// contact, beside brute force (every point through the tool BSP) and FCL on the same data, and
// beside the engine of commit 1f546f3 (rows "previous"), with each query's instruction count from
// callgrind, so that a speed-up is a ratio from one run and a count no machine's noise moves.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define STENCIL_BENCH_CALLGRIND 1
#else  // no valgrind (toolchain/install-deps.sh installs it): the bench counts nothing
#define STENCIL_BENCH_CALLGRIND 0
#endif

// STENCIL_BENCH_PREVIOUS: this file compiled against the engine of commit 1f546f3
// (toolchain/bench-previous.sh), whose headers lived elsewhere and which had no wall's feel.
#if defined(STENCIL_BENCH_PREVIOUS)
#include "firmware/stencil/contact_query.hpp"
#include "firmware/stencil/virtual_tool.hpp"
#include "firmware/tables/table_loader.hpp"
#else
#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/stencil/passivity_controller.hpp"
#include "firmware/core/stencil/speed_penalty.hpp"
#include "firmware/core/stencil/surface_friction.hpp"
#include "firmware/core/stencil/velocity_filter.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#endif
#include "tests/bench/fcl_reference.hpp"
#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/table_generator.hpp"
#include "toolchain/tablegen/tool_option.hpp"

namespace {

using namespace stencil;
using Clock = std::chrono::steady_clock;

// The bench part: a finely tessellated open height field over [5, 45] x [2.5, 22.5] mm, a flat
// lower level at z = 3 for x < 25 and an upper level at z = 6 beyond, so it has flat faces and a
// concave corner where the lower level meets the step.
constexpr double kLow = 3.0, kHigh = 6.0, kStepX = 25.0;
constexpr double kToolRadius = 1.5;  // the bench's tool: ball:d=3

std::vector<tablegen::Facet> stepped_field(std::size_t triangles) {
  const double width = 40.0, depth = 20.0, x0 = 5.0, y0 = 2.5;
  const double cells = static_cast<double>(triangles) / 2.0;
  const auto n = static_cast<std::size_t>(std::max(2.0, std::round(std::sqrt(cells * width / depth))));
  const auto m = static_cast<std::size_t>(std::max(2.0, std::round(cells / static_cast<double>(n))));
  const auto at = [&](std::size_t i, std::size_t j) {
    const double x = x0 + width * static_cast<double>(i) / static_cast<double>(n);
    return Eigen::Vector3d(x, y0 + depth * static_cast<double>(j) / static_cast<double>(m), x < kStepX ? kLow : kHigh);
  };
  std::vector<tablegen::Facet> facets;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < m; ++j) {
      facets.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      facets.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return facets;
}

struct Timing {
  double median_us;
  double p999_us;
  double max_us;
  std::size_t samples;
  std::size_t batch;  // runs of the work per sample (each sample their mean)
};

// Work this short is timed in batches: a read of the clock costs tens of nanoseconds here and
// comes in steps of about 10 ns, as long as a query in free space, so one run between two reads
// times the clock more than the work.
constexpr double kShortestTimedAlone_us = 1.0;
constexpr double kBatchLength_us = 2.0;
constexpr std::size_t kCalibrationBatch = 100;

// One sample: `runs` runs of `work` back to back, their mean in microseconds.
template <typename Work>
double time_batch(Work&& work, std::size_t runs) {
  const auto begin = Clock::now();
  for (std::size_t run = 0; run < runs; ++run) {
    work();
  }
  const auto end = Clock::now();
  return std::chrono::duration<double, std::micro>(end - begin).count() / static_cast<double>(runs);
}

// The median, 99.9th percentile and maximum of the samples (sorted here).
Timing timing_of(std::vector<double>& samples, std::size_t batch) {
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  const std::size_t p999 = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.999 * static_cast<double>(n))) - 1);
  return {samples[n / 2], samples[p999], samples.back(), n, batch};
}

// Times `work` up to `iterations` samples or `budget_s` seconds (at least 11 samples), and gives
// their median, 99.9th percentile and maximum in microseconds per run. Work under
// kShortestTimedAlone_us (by the median of eleven runs timed alone) is run back to back in batches
// of about kBatchLength_us (sized from eleven batches of kCalibrationBatch runs, whose clock reads
// are a small part), each sample the batch's mean: the percentiles are then of batch means, which
// smooth a single run's tail. batch > 0 takes that many runs per sample instead.
template <typename Work>
Timing measure(Work&& work, std::size_t iterations, double budget_s, std::size_t batch = 0) {
  const auto median_of_eleven = [&](std::size_t runs) {
    std::array<double, 11> means{};
    for (double& mean : means) {
      mean = time_batch(work, runs);
    }
    std::nth_element(means.begin(), means.begin() + means.size() / 2, means.end());
    return means[means.size() / 2];
  };
  if (batch == 0) {
    batch = 1;
    if (median_of_eleven(1) < kShortestTimedAlone_us) {
      const double run_us = median_of_eleven(kCalibrationBatch);
      batch = static_cast<std::size_t>(std::ceil(kBatchLength_us / std::max(run_us, 0.001)));
    }
  }
  std::vector<double> samples;
  samples.reserve(iterations);
  const auto started = Clock::now();
  for (std::size_t i = 0; i < iterations; ++i) {
    samples.push_back(time_batch(work, batch));
    if (i >= 10 && std::chrono::duration<double>(Clock::now() - started).count() > budget_s) {
      break;
    }
  }
  return timing_of(samples, batch);
}

volatile double sink = 0.0;  // keeps the optimiser from dropping measured work

// The machine's own tail at a given length of work: a fixed chain of dependent arithmetic. On a
// shared or virtual machine the 99.9th percentile of any work of tens of microseconds is inflated
// by interrupts and by the host taking the CPU away; a baseline as long as a cycle, in the same
// run, shows how much of a measured tail is the machine's rather than the code's.
void baseline_chain(std::size_t steps) {
  double value = sink;
  for (std::size_t i = 0; i < steps; ++i) {
    value = value * 0.999999 + 1e-9;
  }
  sink = value;
}

// The chain's steps for a median of `median_us`, calibrated on the median of short runs.
std::size_t baseline_steps(double median_us) {
  std::size_t steps = 1000;
  for (int round = 0; round < 3; ++round) {
    const Timing t = measure([&] { baseline_chain(steps); }, 200, 0.5);
    steps = std::max<std::size_t>(1, static_cast<std::size_t>(static_cast<double>(steps) * median_us / t.median_us));
  }
  return steps;
}

// A cycle and its baseline row: the baseline sized to the cycle's median (from a first 500
// samples of it), then the two sampled in turn, a cycle's sample then a baseline's, up to
// `iterations` each or `budget_s` seconds for the two together, `batch` runs to a sample for both. In turn, so that
// both rows meet the same stretches of the machine's noise: timed one after the other, a burst of
// the host's load during one row but not the other moved the ratio of their tails from 0.9 to 1.8
// between runs of the same build.
struct TimedBeside {
  Timing work;
  Timing baseline;
};
template <typename Work>
TimedBeside measure_beside_baseline(Work&& work, std::size_t iterations, double budget_s) {
  const Timing first = measure(work, 500, 0.5);
  const std::size_t steps = baseline_steps(first.median_us);
  const std::size_t batch = first.batch;
  std::vector<double> ours;
  std::vector<double> theirs;
  ours.reserve(iterations);
  theirs.reserve(iterations);
  const auto started = Clock::now();
  for (std::size_t i = 0; i < iterations; ++i) {
    ours.push_back(time_batch(work, batch));
    theirs.push_back(time_batch([&] { baseline_chain(steps); }, batch));
    if (i >= 10 && std::chrono::duration<double>(Clock::now() - started).count() > budget_s) {
      break;
    }
  }
  return {timing_of(ours, batch), timing_of(theirs, batch)};
}

struct State {
  const char* name;
  Eigen::Vector3d desired;  // the device's tip
  Eigen::Vector3d resting;  // a legal tip next to it, where the virtual tool starts the cycle
};

// Brute force: every point of the table through the tool BSP.
std::size_t brute_force(const tables::PartTables& part, const Eigen::Vector3d& tip) {
  std::size_t penetrating = 0;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const auto& p = part.points[i];
    const auto c = geometry::classify_at_pose(part.tool, tip, Eigen::Vector3d::UnitZ(), {p.x_mm, p.y_mm, p.z_mm});
    penetrating += c.contact == geometry::PointContact::Penetrating ? 1 : 0;
  }
  return penetrating;
}

struct Options {
  bool json = false;
  bool references = true;
  bool previous = true;      // the "previous" rows, from the engine of commit 1f546f3
  bool instructions = true;  // each query's instructions and L1 misses under callgrind
  bool tablegen = true;      // the table generator's time on a million-triangle part, both engines
  std::string only_state;    // empty: every state
  std::vector<std::size_t> sizes = {10'000, 100'000, 1'000'000};
  std::string previous_path;  // the previous engine's stencil-bench
  std::string table_path;     // --table: time (or count) this table instead of generating one
  std::string write_table;    // --write-table: generate the table for --points and write it here
  bool count_queries = false; // --count-queries: one query per state under callgrind (internal)
};

const std::vector<State>& states() {
  static const std::vector<State> all = {
      {"free", {15.0, 12.5, 9.0}, {15.0, 12.5, 9.0}},
      {"light", {15.0, 12.5, kLow - 0.05}, {15.0, 12.5, kLow + 0.001}},
      {"deep", {15.0, 12.5, kLow - 0.5}, {15.0, 12.5, kLow + 0.001}},
      {"deep-corner", {kStepX - kToolRadius + 0.5, 12.5, kLow - 0.5}, {kStepX - kToolRadius - 0.3, 12.5, kLow + 0.001}},
  };
  return all;
}

// The bench part's table at about `target` points, from the table generator in memory.
std::vector<unsigned char> bench_table(std::size_t target) {
  // About a third as many triangles as points; the rest of the points seeded on the surface.
  const std::vector<tablegen::Facet> facets = stepped_field(target / 3);
  tablegen::GeneratorOptions options;
#if !defined(STENCIL_BENCH_PREVIOUS)  // then the generator's default workspace was this one
  const auto& workspace = board::sherline_suzuki::kRig.workspace_mm;  // the rig's, as stencil-tablegen's
  options.placement.workspace_mm = {workspace[0], workspace[1], workspace[2]};
#endif
  options.tool = tablegen::parse_tool("ball:d=3", "");
  options.spacing_mm = 50.0;  // fine triangles: vertices and centroids, no subdivision
  options.force = true;
  options.extra_points = target - std::min<std::size_t>(target, facets.size() * 3 / 2);
  options.threads = 2;
  tablegen::GeneratorReport report;
  tablegen::TableContents contents = tablegen::generate_tables(tablegen::encode_stl(facets, true, "bench"),
                                                               "bench.stl", options, report, [](const char*, double) {});
  const tablegen::TableBytes bytes = tablegen::assemble_table(contents);
  const auto* first = reinterpret_cast<const unsigned char*>(bytes.data());
  return {first, first + bytes.size()};
}

bool read_file(const std::string& path, std::vector<unsigned char>& bytes) {
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (in == nullptr) {
    return false;
  }
  bytes.clear();
  unsigned char block[65536];
  for (std::size_t n = std::fread(block, 1, sizeof block, in); n > 0; n = std::fread(block, 1, sizeof block, in)) {
    bytes.insert(bytes.end(), block, block + n);
  }
  const bool whole = std::ferror(in) == 0;
  std::fclose(in);
  return whole;
}

bool write_file(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

// Under callgrind (--instr-atstart=no --collect-atstart=no): one query of `state` after one
// uncounted query at the same pose (code and data as warm as in the cycle, which queries next to
// where it queried a millisecond before), counted alone.
int count_one_query(const tables::PartTables& part, const std::string& state_name) {
  const State* state = nullptr;
  for (const State& s : states()) {
    state = s.name == state_name ? &s : state;
  }
#if STENCIL_BENCH_CALLGRIND
  if (state == nullptr || RUNNING_ON_VALGRIND == 0) {
    std::fprintf(stderr, "stencil-bench: --count-queries needs --state and callgrind\n");
    return 2;
  }
  const engine::ToolPose pose{state->desired, Eigen::Vector3d::UnitZ()};
  const engine::ContactParameters parameters{};
  CALLGRIND_START_INSTRUMENTATION;
  sink = sink + engine::query_contacts(part, pose, parameters).max_depth_mm;
  CALLGRIND_TOGGLE_COLLECT;
  const engine::ContactResult counted = engine::query_contacts(part, pose, parameters);
  CALLGRIND_TOGGLE_COLLECT;
  CALLGRIND_STOP_INSTRUMENTATION;
  std::printf("%u\n", counted.penetrating_points);
  return 0;
#else
  static_cast<void>(part);
  std::fprintf(stderr, "stencil-bench: built without valgrind's header: --count-queries counts nothing\n");
  return 2;
#endif
}

std::string shell_quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) {
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return out + "'";
}

// One query's instructions and L1 misses (instruction fetch plus data read and write), counted by
// callgrind with its simulated caches pinned: the same from run to run and machine to machine for
// the same binary and table (the binary's own instructions depend on the ISA it was built for:
// STENCIL_HOST_ISA, AVX2 on these machines).
struct QueryCount {
  bool ok = false;
  std::uint64_t instructions = 0;
  std::uint64_t l1_misses = 0;
};

QueryCount count_query(const std::string& bench, const std::string& table, const std::string& state,
                       const std::string& scratch) {
  const std::string out = scratch + "/callgrind." + state;
  // The simulated caches pinned (32 KiB, 8-way L1s, 8 MiB LL), not taken from this machine's CPU.
  const std::string command = "valgrind --tool=callgrind --cache-sim=yes --I1=32768,8,64 --D1=32768,8,64 "
                              "--LL=8388608,16,64 --instr-atstart=no --collect-atstart=no "
                              "--callgrind-out-file=" + shell_quoted(out) + " " + shell_quoted(bench) + " --count-queries --table " +
                              shell_quoted(table) + " --state " + state + " > /dev/null 2>&1";
  QueryCount count;
  if (std::system(command.c_str()) != 0) {
    return count;
  }
  std::ifstream in(out);
  std::vector<std::string> events;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "events:") {
      for (std::string event; words >> event;) {
        events.push_back(event);
      }
    } else if (key == "totals:") {  // not "summary:", which callgrind leaves at 0 when collection starts off
      for (std::size_t i = 0; i < events.size(); ++i) {
        std::uint64_t value = 0;
        words >> value;
        count.instructions += events[i] == "Ir" ? value : 0;
        count.l1_misses += events[i] == "I1mr" || events[i] == "D1mr" || events[i] == "D1mw" ? value : 0;
      }
      count.ok = !events.empty();
      break;
    }
  }
  std::error_code ignored;
  std::filesystem::remove(out, ignored);
  return count;
}

// Runs `command` and returns its standard output's lines (empty when it failed).
std::vector<std::string> output_lines(const std::string& command) {
  std::vector<std::string> lines;
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    return lines;
  }
  std::string line;
  for (int c = std::fgetc(pipe); c != EOF; c = std::fgetc(pipe)) {
    if (c == '\n') {
      lines.push_back(line);
      line.clear();
    } else {
      line += static_cast<char>(c);
    }
  }
  if (pclose(pipe) != 0) {
    lines.clear();
  }
  return lines;
}

// A field of one of this bench's own JSON rows (numbers and strings without escapes).
std::string json_field(const std::string& row, const std::string& name) {
  const std::string key = "\"" + name + "\": ";
  const std::size_t at = row.find(key);
  if (at == std::string::npos) {
    return {};
  }
  std::size_t begin = at + key.size();
  std::size_t end = begin;
  if (row[begin] == '"') {
    end = row.find('"', ++begin);
  } else {
    end = row.find_first_of(",}", begin);
  }
  return row.substr(begin, end - begin);
}

struct Row {
  std::uint32_t points = 0;
  std::uint32_t triangles = 0;
  std::string state, impl, what;
  Timing timing{};
  QueryCount count{};
};

void print_row(const Options& options, const Row& row) {
  const std::string instructions = row.count.ok ? std::to_string(row.count.instructions) : "";
  const std::string misses = row.count.ok ? std::to_string(row.count.l1_misses) : "";
  if (options.json) {
    const std::string counted =
        row.count.ok ? ", \"instructions\": " + instructions + ", \"l1_misses\": " + misses : std::string();
    std::printf(
        "{\"points\": %u, \"triangles\": %u, \"state\": \"%s\", \"impl\": \"%s\", \"what\": \"%s\", "
        "\"median_us\": %.3f, \"p999_us\": %.3f, \"max_us\": %.3f, \"samples\": %zu, \"batch\": %zu%s}\n",
        row.points, row.triangles, row.state.c_str(), row.impl.c_str(), row.what.c_str(), row.timing.median_us,
        row.timing.p999_us, row.timing.max_us, row.timing.samples, row.timing.batch, counted.c_str());
  } else {
    std::printf("%9u %-12s %-12s %-8s %10.3f %10.3f %10.3f %8zu %6zu %12s %9s\n", row.points, row.state.c_str(),
                row.impl.c_str(), row.what.c_str(), row.timing.median_us, row.timing.p999_us, row.timing.max_us,
                row.timing.samples, row.timing.batch, instructions.c_str(), misses.c_str());
  }
  std::fflush(stdout);
}

#if !defined(STENCIL_BENCH_PREVIOUS)  // the previous engine's rows are its query and cycle only
// How much memory a table takes (it is locked in memory on the rig): one line per engine and size.
void print_table_size(const Options& options, const char* impl, std::uint32_t points, std::uint32_t triangles,
                      std::uintmax_t bytes) {
  const double per_million = points > 0 ? static_cast<double>(bytes) / static_cast<double>(points) : 0.0;
  if (options.json) {
    std::printf("{\"points\": %u, \"triangles\": %u, \"impl\": \"%s\", \"what\": \"table\", \"bytes\": %ju, "
                "\"mb_per_million_points\": %.2f}\n",
                points, triangles, impl, bytes, per_million);
  } else {
    std::printf("%9u %-12s %-12s %-8s %10ju bytes: %.2f MB per million points\n", points, "-", impl, "table", bytes,
                per_million);
  }
  std::fflush(stdout);
}
#endif

// The previous engine's rows for one state, from its own bench on its own table (same harness,
// same machine, right after this engine's rows): its "stencil" rows, as impl "previous".
std::vector<Row> previous_rows(const Options& options, const std::string& table, const State& state,
                               const QueryCount& count) {
  std::vector<Row> rows;
  const std::string command = shell_quoted(options.previous_path) +
                              " --json --stencil-only --no-previous --no-instructions --no-tablegen --table " +
                              shell_quoted(table) + " --state " + state.name;
  for (const std::string& line : output_lines(command)) {
    if (json_field(line, "impl") != "stencil") {
      continue;  // its baselines: this run's own are the reference
    }
    Row row;
    row.points = static_cast<std::uint32_t>(std::stoul(json_field(line, "points")));
    row.triangles = static_cast<std::uint32_t>(std::stoul(json_field(line, "triangles")));
    row.state = state.name;
    row.impl = "previous";
    row.what = json_field(line, "what");
    row.timing = {std::stod(json_field(line, "median_us")), std::stod(json_field(line, "p999_us")),
                  std::stod(json_field(line, "max_us")), std::stoul(json_field(line, "samples")), 1};
    // A bench built before batches had none: each run timed alone.
    const std::string batch = json_field(line, "batch");
    row.timing.batch = batch.empty() ? 1 : std::stoul(batch);
    row.count = row.what == "query" ? count : QueryCount{};
    rows.push_back(row);
  }
  return rows;
}

std::string self_path() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string() : self.string();
}

// This engine's rows for one state: the query, the cycle and its baseline, the cycle with the
// wall's feel and its baseline, and the references.
void state_rows(const Options& options, const tables::PartTables& part, const bench::FclReference* fcl,
                const State& state, const QueryCount& count) {
  const engine::ContactParameters parameters{};
  Row row;
  row.points = part.point_count();
  row.triangles = part.triangle_count();
  row.state = state.name;
  const auto emit = [&](const char* impl, const char* what, const Timing& timing, const QueryCount& counted) {
    row.impl = impl;
    row.what = what;
    row.timing = timing;
    row.count = counted;
    print_row(options, row);
  };
  const engine::ToolPose pose{state.desired, Eigen::Vector3d::UnitZ()};
  const Timing query =
      measure([&] { sink = sink + engine::query_contacts(part, pose, parameters).max_depth_mm; }, 5000, 2.0);
  emit("stencil", "query", query, count);
  const TimedBeside cycle = measure_beside_baseline(
      [&] {
        engine::VirtualTool tool(part, state.resting);
        const engine::ContactResult contact = engine::query_contacts(part, pose, parameters);
        const engine::RemediationResult result = tool.step(state.desired, contact, parameters);
        sink = sink + contact.max_depth_mm + result.tip_mm.z();
      },
      5000, 4.0);
  emit("stencil", "cycle", cycle.work, {});
  emit("baseline", "cycle", cycle.baseline, {});
#if !defined(STENCIL_BENCH_PREVIOUS)
  // The same cycle with the wall's feel on (issue 29), on its longest path as Controller::move_tool
  // and wall_damping take it: the friction cone (a coefficient low enough that a tool resting on
  // the part slides), the probe under the resting tool and the query at the friction's goal, then
  // the velocity filters, the damper, the passivity observer and controller, the speed penalty
  // (its velocity predictor left out: a few multiplications), and the force.
  const TimedBeside felt = measure_beside_baseline(
      [&] {
        engine::VirtualTool tool(part, state.resting);
        const engine::ContactResult contact = engine::query_contacts(part, pose, parameters);
        const engine::FrictionGoal goal = engine::friction_goal(tool.tip_mm(), state.desired, contact, 10.0, 0.05);
        engine::RemediationResult result{};
        bool moved = false;
        if (goal.in_contact && contact.force_n.norm() > 0.0) {
          const engine::ContactResult below =
              tool.contact_at(tool.tip_mm() - 0.01 * contact.force_n.normalized(), parameters);
          if (below.penetrating_points > 0 && !goal.sticking) {
            result = tool.step(goal.goal_mm, tool.contact_at(goal.goal_mm, parameters), parameters);
            moved = true;
          }
        }
        if (!moved) {
          result = tool.step(state.desired, contact, parameters);
        }
        engine::VelocityFilter stretch_rate, handle_velocity;
        stretch_rate.configure(engine::VelocityFilter::kDefaultCutoffHz, 1e-3);
        handle_velocity.configure(engine::VelocityFilter::kDefaultCutoffHz, 1e-3);
        engine::PassivityController passivity;
        const Eigen::Vector3d stretch = 1e-2 * (result.tip_mm - state.desired);
        static_cast<void>(stretch_rate.update(stretch));
        static_cast<void>(handle_velocity.update(1e-2 * state.desired));
        static_cast<void>(passivity.observe(contact.force_n, 1e-5 * Eigen::Vector3d::Ones()));
        const Eigen::Vector3d velocity = handle_velocity.update(1e-2 * state.desired + Eigen::Vector3d::Constant(1e-5));
        const Eigen::Vector3d added = 30.0 * stretch_rate.update(stretch + Eigen::Vector3d::Constant(1e-6)) +
                                      passivity.correction(velocity, 1e-3, 5.0) +
                                      engine::speed_penalty_n(velocity, engine::mill_speed_along(velocity, 0.01, 0.01), 5.0);
        const engine::HapticOutput out =
            engine::haptic_output(state.desired, result.tip_mm, contact, engine::HapticLimits{}, added);
        sink = sink + contact.max_depth_mm + result.tip_mm.z() + out.force_n.x();
      },
      5000, 4.0);
  emit("stencil+feel", "cycle", felt.work, {});
  emit("baseline", "cycle", felt.baseline, {});
#endif
  if (fcl == nullptr) {
    return;
  }
  emit("bruteforce", "query",
       measure([&] { sink = sink + static_cast<double>(brute_force(part, state.desired)); }, 200, 2.0), {});
  const double tip[3] = {state.desired.x(), state.desired.y(), state.desired.z()};
  emit("fcl", "query",
       measure([&] { sink = sink + fcl->query(tip, true, kToolRadius, part.tool.envelope.flute_length_mm).max_depth_mm; },
               500, 2.0),
       {});
}

// The table generator on a million-triangle bench part, this engine's and the previous one's,
// alternately five times each: rows with what "tablegen", the median of the five runs as
// median_us and the slowest as p999_us and max_us (a single run moves by a quarter on these
// machines; alternating shares the noise out between the two).
void tablegen_rows(const Options& options, const std::string& scratch) {
  const std::string stl = scratch + "/million.stl";
  const std::vector<std::byte> bytes = tablegen::encode_stl(stepped_field(1'000'000), true, "bench");
  std::vector<unsigned char> copy(bytes.size());
  std::memcpy(copy.data(), bytes.data(), bytes.size());
  if (!write_file(stl, copy)) {
    std::fprintf(stderr, "stencil-bench: cannot write %s\n", stl.c_str());
    return;
  }
  const std::string here = std::filesystem::path(self_path()).parent_path().string() + "/stencil-tablegen";
  const std::string before = std::filesystem::path(options.previous_path).parent_path().string() + "/stencil-tablegen";
  constexpr int kRounds = 5;
  std::vector<double> seconds[2];
  for (int round = 0; round < kRounds; ++round) {
    for (int which = 0; which < 2; ++which) {
      // Its warnings (the bench part is an open mesh, with no allowance) are known: kept in a file,
      // shown only when it fails.
      const std::string messages = scratch + "/tablegen.stderr";
      const std::string command = shell_quoted(which == 0 ? here : before) + " " + shell_quoted(stl) +
                                  " --tool ball:d=3 --spacing 50 --force --quiet -o " +
                                  shell_quoted(scratch + "/million.stbl") + " 2> " + shell_quoted(messages);
      const auto begin = Clock::now();
      if (std::system(command.c_str()) != 0) {
        std::fprintf(stderr, "stencil-bench: %s failed:\n", command.c_str());
        static_cast<void>(std::system(("cat " + shell_quoted(messages) + " >&2").c_str()));
        return;
      }
      seconds[which].push_back(std::chrono::duration<double>(Clock::now() - begin).count());
    }
  }
  for (int which = 0; which < 2; ++which) {
    std::vector<double> runs = seconds[which];
    std::sort(runs.begin(), runs.end());
    Row row;
    row.triangles = 1'000'000;
    row.state = "-";
    row.impl = which == 0 ? "stencil" : "previous";
    row.what = "tablegen";
    row.timing = {runs[kRounds / 2] * 1e6, runs.back() * 1e6, runs.back() * 1e6, static_cast<std::size_t>(kRounds), 1};
    print_row(options, row);
  }
}

constexpr const char* kUsage =
    "usage: stencil-bench [--json] [--quick | --large | --points N] [--stencil-only] [--state NAME]\n"
    "                     [--no-previous | --previous PATH] [--no-instructions] [--no-tablegen] [--table FILE]\n"
    "Times the collision query and the full cycle (query + remediation with sweep) on parts of\n"
    "1e4, 1e5 and 1e6 points (--quick: the first two) in free space, light contact (0.05 mm into a\n"
    "face), deep contact (0.5 mm into a face) and deep in a concave corner, beside brute force and\n"
    "FCL. --large: only 1e6 points; --points N: only about N. --stencil-only: leave out brute force\n"
    "and FCL. --state free|light|deep|deep-corner: only that state (for profiling one case).\n"
    "Times are in microseconds per run. Work under 1 us (a read of the clock costs tens of ns) is\n"
    "timed in batches of about 2 us run back to back, each sample a batch's mean: column \"batch\"\n"
    "gives the runs per sample (1: each run timed alone); such a row's p999 and max are of batch means.\n"
    "After each cycle row, impl \"baseline\": a fixed arithmetic loop sized to that cycle's median\n"
    "(from a first 500 samples of the cycle), timed the same way and sampled in turn with it (a\n"
    "cycle's sample, then a baseline's), so that both meet the same noise and the machine's own\n"
    "tail can be told from the code's.\n"
    "Impl \"stencil+feel\": the cycle with the wall's feel on (friction, damping, passivity, the\n"
    "speed penalty), on its longest path (the probe under a resting tool and the query at the\n"
    "friction's goal).\n"
    "Impl \"previous\": the same query and cycle with the engine of commit 1f546f3 (before the packed\n"
    "leaf layout), built by toolchain/bench-previous.sh (make bench does) into build/previous/bin and\n"
    "run on its own table of the same part right after this engine's rows; --previous PATH names\n"
    "that bench elsewhere, --no-previous leaves the rows out.\n"
    "Query rows carry \"instructions\" and \"l1_misses\": one query (after one uncounted query at the\n"
    "same pose) under valgrind's callgrind, its simulated caches pinned (32 KiB L1s, 8 MiB LL): the\n"
    "same from run to run for the same binary and table (--no-instructions: leave them out).\n"
    "What \"tablegen\": stencil-tablegen on a million-triangle bench part, this tree's and the previous\n"
    "engine's, alternately five times each; median_us is the median run, p999_us the slowest\n"
    "(--no-tablegen, --quick and --points leave it out).\n"
    "--table FILE: time this table (of the bench part) instead of generating one.\n"
    "What \"table\": the bytes of this engine's table of the bench part and of the previous engine's,\n"
    "and how many MB that is per million points (tables are locked in memory on the rig).\n"
    "--json: one JSON object per line.\n";

// 0: parsed; otherwise the exit status (2 for a bad command line, 0 for --help).
int parse_options(int argc, char** argv, Options& options) {
  std::filesystem::path previous = std::filesystem::path(self_path()).parent_path() / "../previous/bin/stencil-bench";
  options.previous_path = previous.lexically_normal().string();
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    const bool has_value = i + 1 < argc;
    if (argument == "--json") {
      options.json = true;
    } else if (argument == "--quick") {
      options.sizes = {10'000, 100'000};
      options.tablegen = false;
    } else if (argument == "--large") {
      options.sizes = {1'000'000};
    } else if (argument == "--points" && has_value) {
      char* end = nullptr;
      const unsigned long long points = std::strtoull(argv[++i], &end, 10);
      if (*end != '\0' || points < 100 || points > 4'000'000) {
        std::fprintf(stderr, "stencil-bench: --points %s: expected a whole number from 100 to 4000000\n", argv[i]);
        return 2;
      }
      options.sizes = {static_cast<std::size_t>(points)};
      options.tablegen = false;
    } else if (argument == "--stencil-only") {
      options.references = false;
    } else if (argument == "--no-previous") {
      options.previous = false;
    } else if (argument == "--previous" && has_value) {
      options.previous_path = argv[++i];
    } else if (argument == "--no-instructions") {
      options.instructions = false;
    } else if (argument == "--no-tablegen") {
      options.tablegen = false;
    } else if (argument == "--table" && has_value) {
      options.table_path = argv[++i];
    } else if (argument == "--write-table" && has_value) {
      options.write_table = argv[++i];
    } else if (argument == "--count-queries") {
      options.count_queries = true;
    } else if (argument == "--state" && has_value) {
      options.only_state = argv[++i];
      if (options.only_state != "free" && options.only_state != "light" && options.only_state != "deep" &&
          options.only_state != "deep-corner") {
        std::fprintf(stderr, "stencil-bench: --state %s: expected free, light, deep or deep-corner\n", argv[i]);
        return 2;
      }
    } else {
      std::printf("%s", kUsage);
      return argument == "--help" || argument == "-h" ? -1 : 2;
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const int parsed = parse_options(argc, argv, options); parsed != 0) {
    return parsed < 0 ? 0 : parsed;
  }
  if (!options.write_table.empty()) {
    return write_file(options.write_table, bench_table(options.sizes.front())) ? 0 : 1;
  }
  if (options.previous && (options.table_path.size() > 0 || !std::filesystem::exists(options.previous_path))) {
    if (options.table_path.empty()) {
      std::fprintf(stderr, "stencil-bench: no previous engine at %s (toolchain/bench-previous.sh builds it): "
                   "no \"previous\" rows\n", options.previous_path.c_str());
    }
    options.previous = false;
  }
  if (options.instructions && !options.count_queries && std::system("valgrind --version > /dev/null 2>&1") != 0) {
    std::fprintf(stderr, "stencil-bench: valgrind is not installed (toolchain/install-deps.sh): no instruction counts\n");
    options.instructions = false;
  }
  std::error_code error;
  std::string pattern = (std::filesystem::temp_directory_path(error) / "stencil-bench.XXXXXX").string();
  if (error || mkdtemp(pattern.data()) == nullptr) {
    std::fprintf(stderr, "stencil-bench: cannot make a scratch folder in the temporary folder\n");
    return 1;
  }
  const std::string scratch = pattern;
  struct Remove {
    std::string path;
    ~Remove() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } const remove_scratch{scratch};
  if (!options.json && !options.count_queries) {
    std::printf("%9s %-12s %-12s %-8s %10s %10s %10s %8s %6s %12s %9s\n", "points", "state", "impl", "what",
                "median_us", "p999_us", "max_us", "samples", "batch", "instructions", "l1_misses");
  }
  int status = 0;
  const std::vector<std::size_t> sizes = options.table_path.empty() ? options.sizes : std::vector<std::size_t>{0};
  for (const std::size_t target : sizes) {
    std::vector<unsigned char> bytes;
    const std::string table = options.table_path.empty() ? scratch + "/stencil.stbl" : options.table_path;
    if (options.table_path.empty()) {
      bytes = bench_table(target);
      write_file(table, bytes);
    } else if (!read_file(table, bytes)) {
      std::fprintf(stderr, "stencil-bench: %s: cannot be read\n", table.c_str());
      return 1;
    }
    tables::PartTables part{};
    const tables::TableLoadResult loaded =
        tables::load_tables({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, part);
    if (!loaded.ok) {
      std::fprintf(stderr, "stencil-bench: the bench table did not load: %s\n", loaded.field);
      return 1;
    }
    if (options.count_queries) {
      return count_one_query(part, options.only_state);
    }
    const std::string previous_table = scratch + "/previous.stbl";
    if (options.previous &&
        std::system((shell_quoted(options.previous_path) + " --points " + std::to_string(target) + " --write-table " +
                     shell_quoted(previous_table)).c_str()) != 0) {
      std::fprintf(stderr, "stencil-bench: %s could not write its table: no \"previous\" rows\n",
                   options.previous_path.c_str());
      options.previous = false;
    }
#if !defined(STENCIL_BENCH_PREVIOUS)
    print_table_size(options, "stencil", part.point_count(), part.triangle_count(), bytes.size());
    std::error_code size_error;
    const std::uintmax_t previous_bytes = options.previous ? std::filesystem::file_size(previous_table, size_error) : 0;
    if (options.previous && !size_error) {
      // Of the same part, by the same point sampling: the same points.
      print_table_size(options, "previous", part.point_count(), part.triangle_count(), previous_bytes);
    }
#endif
    std::vector<float> triangles(9 * part.triangle_count());
    std::memcpy(triangles.data(), part.triangles, triangles.size() * sizeof(float));
    const bench::FclReference fcl(triangles.data(), part.triangle_count());
    for (const State& state : states()) {
      if (!options.only_state.empty() && options.only_state != state.name) {
        continue;
      }
      const std::string self = self_path();
      const QueryCount count = options.instructions ? count_query(self, table, state.name, scratch) : QueryCount{};
      state_rows(options, part, options.references ? &fcl : nullptr, state, count);
      if (options.previous) {
        const QueryCount before =
            options.instructions ? count_query(options.previous_path, previous_table, state.name, scratch) : QueryCount{};
        const std::vector<Row> rows = previous_rows(options, previous_table, state, before);
        if (rows.empty()) {
          std::fprintf(stderr, "stencil-bench: the previous engine's bench gave no rows for %s\n", state.name);
          status = 1;
        }
        for (const Row& row : rows) {
          print_row(options, row);
        }
      }
    }
  }
  if (options.tablegen && options.previous) {
    tablegen_rows(options, scratch);
  }
  return status;
}
