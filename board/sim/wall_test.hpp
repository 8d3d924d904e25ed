// The wall's feel, measured (issue 29): a simulated hand and device (sim/operator/hand_device_model)
// tap and slide on the part's top face through the real cycle (control::Controller) over a direct
// device link, and what the hand felt is summed up per case: the first rebound, the oscillation left
// 100 ms after contact, the energy the wall put into the hand, and sliding, the friction it felt.
// And in free space above the part, with the mill's speed cap on: a hand pushing on faster than the
// mill can follow, the speed it is held to and how it settles there; and a handle let go.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "hal/haptic_device.hpp"
#include "sim/operator/hand_device_model.hpp"

namespace stencil::board::sim {

enum class WallRendering : std::uint8_t {
  Previous,  // today's: the coupling's spring and the contact force, nothing else (speed: the cap alone)
  New,       // with the virtual damper and the passivity controller (new_wall_feel); speed: the cap and
             // the speed penalty (engine/speed_penalty.hpp)
};
// Speed: a hand pushing on at twice the mill's speed in free space, the speed cap on. Release: the
// hand lets go and the coupling pulls the bare handle towards the virtual tool.
enum class WallTestKind : std::uint8_t { Tap, Slide, Speed, Release };

[[nodiscard]] const char* name_of(WallRendering rendering);
[[nodiscard]] const char* name_of(WallTestKind test);

// The couplings the display allows, low to high (N per device mm; control::ControllerConfig's range).
inline constexpr double kWallCouplings[] = {0.05, 0.1, 0.2, 0.5, 1.0, 2.0};

// Each transport's delay from the cycle's command to the device's motors (s), for --transport:
// direct, in process, none; pio and can as the rig expects them (hal/haptic_device.hpp).
inline constexpr double kDirectDelayS = 0.0;
inline constexpr double kPioDelayS = hal::kPioCommandDelayS;
inline constexpr double kCanDelayS = hal::kCanCommandDelayS;

struct WallCase {
  stencil::sim::HandParameters hand = stencil::sim::kMediumHand;
  double coupling_n_per_device_mm = 0.5;
  WallRendering rendering = WallRendering::Previous;
  WallTestKind test = WallTestKind::Tap;
  double speed_device_mm_per_s = 1000.0;  // tap: the hand's speed into the face; slide: along it;
                                          // speed: its intent's along its way (speed_test_case)
  double push_n = 2.0;                    // what the hand pushes into the face with once there (speed:
                                          // the most it pushes with along its way)
  double friction = 0.0;                  // the coefficient set (both renderings take it)
  double transport_delay_s = kDirectDelayS;
  // Speed: the hand's way in the horizontal plane, degrees from +x towards +y (45: where the cap's
  // |dx| + |dy| bound lets the mill follow least).
  double heading_deg = 0.0;
  // Speed and release, the new rendering: how steeply the penalty rises (N s per device m).
  double speed_penalty_slope_n_s_per_m = engine::kSpeedPenaltySlopeNSPerM;
};

struct WallRow {
  WallCase c;
  // Tap, and a slide's press onto the face (a tap at 100 device mm/s): the handle's depth past the
  // face's plane (device mm, + into the part).
  double first_peak_mm = 0.0;     // where the handle first turned back (or the deepest in the first 100 ms)
  double rebound_mm = 0.0;        // the farthest it came back out past the face after first touching it
  // What oscillates from 100 ms after contact (or after the hand stopped pushing in, if later): the
  // largest departure from the least-squares line through the depth over the next 200 ms (a slow
  // settling is not an oscillation), over the first peak.
  double residual_fraction = 0.0;
  double wall_energy_j = 0.0;     // the work the rendered force did on the handle (+: into the hand):
                                  // tap, in and out again; slide, the press and hold
  bool stable = false;            // residual_fraction at most 5 %
  bool passive = false;           // wall_energy_j at most 1e-6 J
  double friction_ratio = 0.0;    // slide: tangential over normal force over the periods the tool slid
  double stuck_slip_mm = 0.0;     // slide: how far the tool moved along the face while held inside the cone (world mm)
  // Speed and release: the handle's speed along the hand's way (release: +x; device mm/s) and how it
  // settled; residual_fraction and stable are then the speed's (what is left 100 ms after its first
  // peak, over that peak).
  double limit_device_mm_per_s = 0.0;       // what the mill follows along the way, at the device
  double held_speed_device_mm_per_s = 0.0;  // the mean over the last 0.5 s
  double steady_max_device_mm_per_s = 0.0;  // the most over the last 0.5 s
  double first_peak_device_mm_per_s = 0.0;  // where the speed first turned back (averaged over 10 ms)
  double lag_device_mm = 0.0;               // how far the virtual tool trails the handle then (mean)
  bool held = false;                        // both speeds over the last 0.5 s below the limit
  std::string error;              // not empty: the case could not run (the cycle went to a safe state ...)
};

// The new rendering at a coupling: virtual damping of 10 + 20 N s/m per N per device mm of the
// wall's stiffness (the coupling plus the contact's), from a sweep over the three hands (a hand
// ringing on the wall dies down to 5 % within 100 ms only with about 60 N s/m per kg of moving mass,
// the more the stiffer the wall; more at a soft wall and the hand creeps in), and the passivity
// controller for whatever energy the sampled wall still puts out.
[[nodiscard]] engine::WallFeel new_wall_feel(double coupling_n_per_device_mm, double contact_stiffness_n_per_device_mm,
                                             double friction);

// The speed the mill can follow along `way` (device space), at the device (device mm/s): the rig's
// cap on the virtual tool (per axis and |dx| + |dy| + |dz|) times the device's scale.
[[nodiscard]] double mill_speed_device_mm_per_s(const Eigen::Vector3d& way);

// A speed case: the hand's intent at `speed_factor` times the mill's speed along its way, heading_deg
// from +x in the horizontal plane, pushing with at most `push_n`, over the CAN link. A release case
// likewise, with test = Release (the row's hand is then "none").
[[nodiscard]] WallCase speed_test_case(const stencil::sim::HandParameters& hand, double coupling_n_per_device_mm,
                                       WallRendering rendering, double speed_factor, double push_n,
                                       double heading_deg = 0.0);

// One case on `part` (its top face, from above the middle of it). Deterministic: virtual time.
[[nodiscard]] WallRow run_wall_case(const tables::PartTables& part, const WallCase& c);

// A row as one line of JSON (issue 29's fields), and as a line of the table.
[[nodiscard]] std::string wall_row_json(const WallRow& row);
[[nodiscard]] std::string wall_row_text(const WallRow& row);
[[nodiscard]] std::string wall_table_header();
// The speed rows' own columns.
[[nodiscard]] std::string speed_table_header();

}  // namespace stencil::board::sim
