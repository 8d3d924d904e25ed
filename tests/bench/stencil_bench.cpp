// stencil-bench: time of the collision query and of the full cycle (query + remediation with its
// sweep) on finely tessellated parts of 1e4, 1e5 and 1e6 points, in free space, in light and deep
// contact, beside brute force (every point through the tool BSP) and FCL on the same data.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/stencil/passivity_controller.hpp"
#include "firmware/core/stencil/speed_penalty.hpp"
#include "firmware/core/stencil/surface_friction.hpp"
#include "firmware/core/stencil/velocity_filter.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
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
};

template <typename Work>
Timing measure(Work&& work, std::size_t iterations, double budget_s) {
  std::vector<double> samples;
  samples.reserve(iterations);
  const auto started = Clock::now();
  for (std::size_t i = 0; i < iterations; ++i) {
    const auto begin = Clock::now();
    work();
    const auto end = Clock::now();
    samples.push_back(std::chrono::duration<double, std::micro>(end - begin).count());
    if (i >= 10 && std::chrono::duration<double>(end - started).count() > budget_s) {
      break;
    }
  }
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  const std::size_t p999 = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.999 * static_cast<double>(n))) - 1);
  return {samples[n / 2], samples[p999], samples.back(), n};
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

volatile double sink = 0.0;  // keeps the optimiser from dropping measured work

// The machine's own tail at a given length of work: a fixed chain of dependent arithmetic, as long
// as `median_us`, timed the same way. On a shared or virtual machine the 99.9th percentile of any
// work of tens of microseconds is inflated by interrupts and by the host taking the CPU away; this
// row, in the same run, shows how much of a measured tail is the machine's rather than the code's.
Timing baseline_of_length(double median_us) {
  const auto chain = [](std::size_t steps) {
    double value = sink;
    for (std::size_t i = 0; i < steps; ++i) {
      value = value * 0.999999 + 1e-9;
    }
    sink = value;
  };
  std::size_t steps = 1000;
  for (int round = 0; round < 3; ++round) {  // calibrate on the median of short runs
    const Timing t = measure([&] { chain(steps); }, 200, 0.5);
    steps = std::max<std::size_t>(1, static_cast<std::size_t>(static_cast<double>(steps) * median_us / t.median_us));
  }
  return measure([&] { chain(steps); }, 5000, 2.0);
}

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  bool references = true;
  std::string only_state;  // empty: every state
  std::vector<std::size_t> sizes = {10'000, 100'000, 1'000'000};
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--json") {
      json = true;
    } else if (argument == "--quick") {
      sizes = {10'000, 100'000};
    } else if (argument == "--large") {
      sizes = {1'000'000};
    } else if (argument == "--stencil-only") {
      references = false;
    } else if (argument == "--state" && i + 1 < argc) {
      only_state = argv[++i];
      if (only_state != "free" && only_state != "light" && only_state != "deep" && only_state != "deep-corner") {
        std::fprintf(stderr, "stencil-bench: --state %s: expected free, light, deep or deep-corner\n", only_state.c_str());
        return 2;
      }
    } else {
      std::printf(
          "usage: stencil-bench [--json] [--quick | --large] [--stencil-only] [--state NAME]\n"
          "Times the collision query and the full cycle (query + remediation with sweep) on parts of\n"
          "1e4, 1e5 and 1e6 points (--quick: the first two) in free space, light contact (0.05 mm into a\n"
          "face), deep contact (0.5 mm into a face) and deep in a concave corner, beside brute force and\n"
          "FCL. --large: only 1e6 points. --stencil-only: leave out brute force and FCL (for profiling).\n"
          "--state free|light|deep|deep-corner: only that state (for profiling one case).\n"
          "After each cycle row, impl \"baseline\": a fixed arithmetic loop as long as that cycle's median,\n"
          "timed the same way, so the machine's own tail can be told from the code's.\n"
          "Impl \"stencil+feel\": the cycle with the wall's feel on (friction, damping, passivity, the\n"
          "speed penalty), on\n"
          "its longest path (the probe under a resting tool and the query at the friction's goal).\n"
          "--json: one JSON object per line.\n");
      return argument == "--help" || argument == "-h" ? 0 : 2;
    }
  }
  if (!json) {
    std::printf("%9s %-12s %-12s %-5s %10s %10s %10s %8s\n", "points", "state", "impl", "what", "median_us",
                "p999_us", "max_us", "samples");
  }
  const double radius = 1.5;
  const std::vector<State> states = {
      {"free", {15.0, 12.5, 9.0}, {15.0, 12.5, 9.0}},
      {"light", {15.0, 12.5, kLow - 0.05}, {15.0, 12.5, kLow + 0.001}},
      {"deep", {15.0, 12.5, kLow - 0.5}, {15.0, 12.5, kLow + 0.001}},
      {"deep-corner", {kStepX - radius + 0.5, 12.5, kLow - 0.5}, {kStepX - radius - 0.3, 12.5, kLow + 0.001}},
  };
  for (const std::size_t target : sizes) {
    // About a third as many triangles as points; the rest of the points seeded on the surface.
    const std::vector<tablegen::Facet> facets = stepped_field(target / 3);
    tablegen::GeneratorOptions options;
    const auto& workspace = board::sherline_suzuki::kRig.workspace_mm;  // the rig's, as stencil-tablegen's
    options.placement.workspace_mm = {workspace[0], workspace[1], workspace[2]};
    options.tool = tablegen::parse_tool("ball:d=3", "");
    options.spacing_mm = 50.0;  // fine triangles: vertices and centroids, no subdivision
    options.force = true;
    options.extra_points = target - std::min<std::size_t>(target, facets.size() * 3 / 2);
    options.threads = 2;
    tablegen::GeneratorReport report;
    tablegen::TableContents contents = tablegen::generate_tables(tablegen::encode_stl(facets, true, "bench"),
                                                                 "bench.stl", options, report, [](const char*, double) {});
    const tablegen::TableBytes bytes = tablegen::assemble_table(contents);
    tables::PartTables part{};
    const tables::TableLoadResult loaded = tables::load_tables({bytes.data(), bytes.size()}, part);
    if (!loaded.ok) {
      std::fprintf(stderr, "stencil-bench: the bench table did not load: %s\n", loaded.field);
      return 1;
    }
    std::vector<float> triangles(9 * part.triangle_count());
    std::memcpy(triangles.data(), part.triangles, triangles.size() * sizeof(float));
    const bench::FclReference fcl(triangles.data(), part.triangle_count());
    const engine::ContactParameters parameters{};

    const auto report_row = [&](const State& state, const char* impl, const char* what, const Timing& t) {
      if (json) {
        std::printf(
            "{\"points\": %u, \"triangles\": %u, \"state\": \"%s\", \"impl\": \"%s\", \"what\": \"%s\", "
            "\"median_us\": %.3f, \"p999_us\": %.3f, \"max_us\": %.3f, \"samples\": %zu}\n",
            part.point_count(), part.triangle_count(), state.name, impl, what, t.median_us, t.p999_us, t.max_us,
            t.samples);
      } else {
        std::printf("%9u %-12s %-12s %-5s %10.2f %10.2f %10.2f %8zu\n", part.point_count(), state.name, impl, what,
                    t.median_us, t.p999_us, t.max_us, t.samples);
      }
      std::fflush(stdout);
    };

    for (const State& state : states) {
      if (!only_state.empty() && only_state != state.name) {
        continue;
      }
      const engine::ToolPose pose{state.desired, Eigen::Vector3d::UnitZ()};
      const Timing query = measure([&] { sink = sink + engine::query_contacts(part, pose, parameters).max_depth_mm; },
                                   5000, 2.0);
      report_row(state, "stencil", "query", query);
      const Timing cycle = measure(
          [&] {
            engine::VirtualTool tool(part, state.resting);
            const engine::ContactResult contact = engine::query_contacts(part, pose, parameters);
            const engine::RemediationResult result = tool.step(state.desired, contact, parameters);
            sink = sink + contact.max_depth_mm + result.tip_mm.z();
          },
          5000, 2.0);
      report_row(state, "stencil", "cycle", cycle);
      report_row(state, "baseline", "cycle", baseline_of_length(cycle.median_us));
      // The same cycle with the wall's feel on (issue 29), on its longest path as Controller::move_tool
      // and wall_damping take it: the friction cone (a coefficient low enough that a tool resting on
      // the part slides), the probe under the resting tool and the query at the friction's goal, then
      // the velocity filters, the damper, the passivity observer and controller, the speed penalty
      // (its velocity predictor left out: a few multiplications), and the force.
      const Timing felt = measure(
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
            const Eigen::Vector3d velocity =
                handle_velocity.update(1e-2 * state.desired + Eigen::Vector3d::Constant(1e-5));
            const Eigen::Vector3d added = 30.0 * stretch_rate.update(stretch + Eigen::Vector3d::Constant(1e-6)) +
                                          passivity.correction(velocity, 1e-3, 5.0) +
                                          engine::speed_penalty_n(velocity, engine::mill_speed_along(velocity, 0.01, 0.01), 5.0);
            const engine::HapticOutput out =
                engine::haptic_output(state.desired, result.tip_mm, contact, engine::HapticLimits{}, added);
            sink = sink + contact.max_depth_mm + result.tip_mm.z() + out.force_n.x();
          },
          5000, 2.0);
      report_row(state, "stencil+feel", "cycle", felt);
      report_row(state, "baseline", "cycle", baseline_of_length(felt.median_us));
      if (!references) {
        continue;
      }
      const Timing brute = measure([&] { sink = sink + static_cast<double>(brute_force(part, state.desired)); },
                                   200, 2.0);
      report_row(state, "bruteforce", "query", brute);
      const double tip[3] = {state.desired.x(), state.desired.y(), state.desired.z()};
      const Timing reference = measure(
          [&] { sink = sink + fcl.query(tip, true, radius, part.tool.envelope.flute_length_mm).max_depth_mm; }, 500,
          2.0);
      report_row(state, "fcl", "query", reference);
    }
  }
  return 0;
}
