// stencil-wall-test: how the part's wall feels (issue 29). A simulated hand taps and slides on the
// baked-in hex prism's top face through the real cycle, for each hand and each coupling the display
// allows, with today's rendering and the new one; a table, or one JSON row per case (--json).
// Exit 0 every case ran and the new rendering is stable and passive in all of them, with the slides'
// friction within 5 % of the coefficient and no slip inside the cone; 1 not (the rows say where);
// 2 usage. The virtual tool's speed limit is off for the taps and slides: the wall's feel, not the
// mill's lag. --test speed is the mill's lag: in free space above the face, the speed limit on, a hand
// pushing on at twice the mill's speed (along +x, or --heading degrees from it), held by the cap alone
// (previous) or by the cap and the speed penalty (new); exit 0 when the new rendering holds every
// hand under the mill's speed, stably.
// --test release lets go of the handle where the coupling pulls it back towards the lagging virtual
// tool with the force limit (no hand: one row per coupling): exit 0 when the new rendering brings it
// to rest stably.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "board/sim/wall_test.hpp"
#include "firmware/core/tables/table_loader.hpp"

extern const unsigned char stencil_table_hex_prism[];
extern const std::size_t stencil_table_hex_prism_size;

namespace {

using namespace stencil::board::sim;

constexpr int kAllWell = 0;
constexpr int kNotWell = 1;
constexpr int kUsage = 2;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stencil-wall-test: taps and slides on the hex prism's top face through the real cycle, for each "
               "simulated hand and coupling, with today's rendering (previous) and the new one (virtual damping and "
               "the passivity controller); prints the first rebound, the oscillation left 100 ms after contact, the "
               "energy the wall put into the hand, and sliding, the friction felt; --test speed: a hand pushing on at "
               "twice the mill's speed with the speed cap on, held by the cap alone (previous) or with the speed "
               "penalty (new); --test release: the handle let go where the coupling pulls it back with the force limit"};
  bool json = false;
  std::string hand_name = "all";
  std::vector<double> couplings(std::begin(kWallCouplings), std::end(kWallCouplings));
  double tap_speed = 1000.0;
  double slide_speed = 50.0;
  double push_n = 2.0;
  double friction = 0.5;
  std::string transport = "can";
  std::string which = "both";
  double speed_factor = 2.0;
  double penalty_slope = stencil::engine::kSpeedPenaltySlopeNSPerM;
  double heading = 0.0;
  app.add_flag("--json", json, "one JSON object per case, one per line");
  app.add_option("--hand", hand_name, "relaxed, medium, stiff or all")->check(CLI::IsMember({"relaxed", "medium", "stiff", "all"}))->capture_default_str();
  app.add_option("--coupling", couplings, "the couplings to test (N per device mm), 0.05 to 2")
      ->check(CLI::Range(0.05, 2.0))->capture_default_str();
  app.add_option("--tap-speed", tap_speed, "the hand's speed into the face (device mm/s)")->check(CLI::Range(1.0, 2000.0))->capture_default_str();
  app.add_option("--slide-speed", slide_speed, "the hand's speed along the face (device mm/s)")->check(CLI::Range(1.0, 1000.0))->capture_default_str();
  app.add_option("--push", push_n, "what the hand pushes into the face with (speed: along its way) (N), under the 5 N limit")->check(CLI::Range(0.1, 4.9))->capture_default_str();
  app.add_option("--friction", friction, "the friction coefficient for the slides (0 to 1)")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--transport", transport, "the device link's delay: direct (0), pio (0.5 ms) or can (0.7 ms)")
      ->check(CLI::IsMember({"direct", "pio", "can"}))->capture_default_str();
  app.add_option("--test", which, "tap, slide, both (tap and slide), speed or release")
      ->check(CLI::IsMember({"tap", "slide", "both", "speed", "release"}))->capture_default_str();
  app.add_option("--speed-factor", speed_factor,
                 "speed: the hand's intent as a multiple of the speed the mill follows (times the device's scale)")
      ->check(CLI::Range(1.0, 10.0))->capture_default_str();
  app.add_option("--heading", heading,
                 "speed: the hand's way in the horizontal plane, degrees from +x towards +y (45: where the mill "
                 "follows least)")
      ->check(CLI::Range(-360.0, 360.0))->capture_default_str();
  app.add_option("--penalty-slope", penalty_slope,
                 "speed: how steeply the new rendering's penalty rises (N s per device m), to measure another")
      ->check(CLI::Range(1.0, 5000.0))->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kAllWell : kUsage;
  }
  stencil::tables::PartTables part{};
  const stencil::tables::TableLoadResult loaded = stencil::tables::load_tables(
      {reinterpret_cast<const std::byte*>(stencil_table_hex_prism), stencil_table_hex_prism_size}, part);
  if (!loaded.ok) {
    std::fprintf(stderr, "stencil-wall-test: the baked-in table does not load: %s\n", loaded.field);
    return kUsage;
  }
  const double delay_s = transport == "direct" ? kDirectDelayS : transport == "pio" ? kPioDelayS : kCanDelayS;
  if (!json) {
    const bool speed_rows = which == "speed" || which == "release";
    std::printf("%s\n", (speed_rows ? speed_table_header() : wall_table_header()).c_str());
  }
  bool all_well = true;
  for (const stencil::sim::HandParameters& hand : stencil::sim::kHandPresets) {
    if (hand_name != "all" && hand.name != hand_name && which != "release") {
      continue;
    }
    if (which == "release" && hand.name != stencil::sim::kHandPresets.front().name) {
      continue;  // no hand holds a released handle: one pass over the couplings, whatever --hand says
    }
    for (const double coupling : couplings) {
      if (which == "speed" || which == "release") {
        for (const WallRendering rendering : {WallRendering::Previous, WallRendering::New}) {
          WallCase c = speed_test_case(hand, coupling, rendering, speed_factor, push_n, heading);
          c.test = which == "speed" ? WallTestKind::Speed : WallTestKind::Release;
          c.transport_delay_s = delay_s;
          c.speed_penalty_slope_n_s_per_m = penalty_slope;
          const WallRow row = run_wall_case(part, c);
          std::printf("%s\n", (json ? wall_row_json(row) : wall_row_text(row)).c_str());
          std::fflush(stdout);
          // A released handle the coupling pulls harder than the penalty holds is not held: only its
          // settling counts there.
          const bool held = row.held || c.test == WallTestKind::Release;
          if (rendering == WallRendering::New && (!row.error.empty() || !held || !row.stable)) {
            all_well = false;
          }
        }
        continue;
      }
      for (const WallTestKind test : {WallTestKind::Tap, WallTestKind::Slide}) {
        if (which != "both" && which != name_of(test)) {
          continue;
        }
        for (const WallRendering rendering : {WallRendering::Previous, WallRendering::New}) {
          WallCase c;
          c.hand = hand;
          c.coupling_n_per_device_mm = coupling;
          c.rendering = rendering;
          c.test = test;
          c.speed_device_mm_per_s = test == WallTestKind::Tap ? tap_speed : slide_speed;
          c.push_n = push_n;
          // Today's rendering has no friction; the new one takes the coefficient on the slides.
          c.friction = test == WallTestKind::Slide && rendering == WallRendering::New ? friction : 0.0;
          c.transport_delay_s = delay_s;
          const WallRow row = run_wall_case(part, c);
          std::printf("%s\n", (json ? wall_row_json(row) : wall_row_text(row)).c_str());
          std::fflush(stdout);
          const bool friction_off = test == WallTestKind::Slide && rendering == WallRendering::New && friction > 0.0 &&
                                    (std::fabs(row.friction_ratio - friction) > 0.05 * friction || row.stuck_slip_mm > 1e-6);
          if (rendering == WallRendering::New && (!row.error.empty() || !row.stable || !row.passive || friction_off)) {
            all_well = false;
          }
        }
      }
    }
  }
  return all_well ? kAllWell : kNotWell;
}
