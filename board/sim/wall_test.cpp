// Taps and slides on the part's top face through the real cycle, and what the hand felt.
#include "board/sim/wall_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include <nlohmann/json.hpp>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/sim_job.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "sim/haptic_device/direct_haptic_device.hpp"

namespace stencil::board::sim {
namespace {

constexpr double kStableFraction = 0.05;   // issue 29: at most 5 % of the first peak left after 100 ms
constexpr double kPassiveEnergyJ = 1e-6;   // issue 29: at most 1 uJ put in per contact
// The new rendering's virtual damping, N s per device metre: 10 plus 20 per N/mm of the wall's
// stiffness (the coupling plus the contact's). From a sweep of 0 to 60 N s/m over the three hands:
// a hand ringing on the wall dies down to 5 % in 100 ms only with about 60 N s/m per kg of moving
// mass, and the stiffer the wall the more; more than that at a soft wall and the hand creeps in.
// How long the drag may take to break the tool loose (periods): at the weakest coupling and hand,
// about 0.8 s.
constexpr int kMaxStickPeriods = 1500;
constexpr double kDampingBaseNSPerM = 10.0;
constexpr double kDampingPerStiffnessNSPerM = 21.0;  // per N per device mm
// A speed case runs this long after the hand first pushes with all its push (a steady state, measured
// over its last 0.5 s), and never longer than the second figure in all.
constexpr double kSpeedSettleS = 2.0;
constexpr double kMaxSpeedCaseS = 10.0;
// A speed falling back from its highest by more than this fraction of its steady value has peaked:
// measured a period at a time it jitters by one or two percent of it (the device's positions come in
// whole micrometres, 1 mm/s a period, and the penalty's damping acts on that).
constexpr double kPeakDropFraction = 0.05;
constexpr std::size_t kPeakSmoothingPeriods = 10;
constexpr double kSteadyWindowS = 0.5;     // a speed case's steady speed: its mean over the last of it
constexpr double kReleaseS = 1.0;

// The part's top face: its height and the middle of the points on it (world mm).
struct Face {
  double top_z = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

Face top_face(const tables::PartTables& part) {
  Face face;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    face.top_z = std::max(face.top_z, static_cast<double>(part.points[i].z_mm));
  }
  int on_top = 0;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const tables::PackedPoint& p = part.points[i];
    if (static_cast<double>(p.z_mm) > face.top_z - 1e-6) {
      face.centre += Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm);
      ++on_top;
    }
  }
  face.centre /= std::max(on_top, 1);
  return face;
}

// What one cycle left behind, for the measurements.
struct Sample {
  double t_s;
  Eigen::Vector3d handle_mm;  // device
  Eigen::Vector3d force_n;    // commanded, device
  Eigen::Vector3d applied_n;  // what the device's motors drove over the period (after the link's delay)
  Eigen::Vector3d tip_mm;     // the virtual tool, world
};

// The cycle with its rings, a direct device and the simulated hand on it: one millisecond per step.
class WallBench {
 public:
  WallBench(const tables::PartTables& part, const WallCase& c, const control::ControllerConfig& config,
            const Eigen::Vector3d& start_device_mm)
      : config_(config),
        device_(rig::kDeviceRange),
        rings_(std::make_unique<control::CycleRingStorage>()),
        controller_(std::make_unique<control::Controller>(part, device_, rings_->rings(), config)),
        model_(stencil::sim::DeviceParameters{0.2, 0.05, 0.0, c.transport_delay_s, stencil::sim::kDefaultSubstepRateHz},
               c.hand, now_ns_, start_device_mm) {}

  [[nodiscard]] bool ready() const { return controller_->ready(); }
  stencil::sim::HandDeviceModel& model() { return model_; }
  [[nodiscard]] double now_s() const { return static_cast<double>(now_ns_ - kStartNs) * 1e-9; }
  [[nodiscard]] const std::vector<Sample>& samples() const { return samples_; }
  [[nodiscard]] control::SafeReason safe_reason() const { return controller_->safe_reason(); }
  [[nodiscard]] const motion::MachineFrames& frames() const { return config_.frames; }

  // One period: the hand and device move to now, the device's sample goes to the cycle, the cycle's
  // command goes to the device. False once the cycle is in a safe state.
  bool step() {
    now_ns_ += kPeriodNs;
    model_.advance_to(now_ns_);
    const Eigen::Vector3d handle = model_.position_mm();
    hal::HapticSample sample{};
    for (int i = 0; i < 3; ++i) {
      sample.position_mm[i] = handle[i];
    }
    sample.sample_counter = ++counter_;
    sample.device_heartbeat = counter_;
    device_.publish(sample);
    const control::CycleStatus status = controller_->step(now_ns_, now_ns_);
    controller_->finish(now_ns_ + 10'000, now_ns_ + kPeriodNs);
    drain();
    const hal::HapticCommand& command = device_.rendered();
    const Eigen::Vector3d force(command.force_n[0], command.force_n[1], command.force_n[2]);
    const Eigen::Vector3d applied = model_.applied_force_n();
    static_cast<void>(model_.command_force(now_ns_, force));
    samples_.push_back({now_s(), handle, force, applied, controller_->virtual_tip_mm()});
    return status == control::CycleStatus::Running;
  }

  // Steps for `seconds`; false when the cycle left the running state on the way.
  bool run_for(double seconds) {
    const auto periods = static_cast<int>(std::lround(seconds * 1e3));
    for (int i = 0; i < periods; ++i) {
      if (!step()) {
        return false;
      }
    }
    return true;
  }

 private:
  static constexpr hal::MonotonicNs kStartNs = 1'000'000'000;

  void drain() {
    control::MachineHandoff handoff{};
    while (rings_->machine.pop(handoff)) {
    }
    control::JournalRecord record{};
    while (rings_->journal.pop(record)) {
    }
    control::Telemetry telemetry{};
    while (rings_->telemetry.pop(telemetry)) {
    }
    control::CommandEvent event{};
    while (rings_->command_events.pop(event)) {
    }
  }

  control::ControllerConfig config_;
  hal::MonotonicNs now_ns_ = kStartNs;
  std::uint32_t counter_ = 0;
  stencil::sim::DirectHapticDevice device_;
  std::unique_ptr<control::CycleRingStorage> rings_;
  std::unique_ptr<control::Controller> controller_;
  stencil::sim::HandDeviceModel model_;
  std::vector<Sample> samples_;
};

// Moves the hand's intent in a straight line to `to` at `speed` (device mm/s), then holds it there.
bool move_intent(WallBench& bench, const Eigen::Vector3d& from, const Eigen::Vector3d& to, double speed) {
  const Eigen::Vector3d way = to - from;
  const double seconds = way.norm() / speed;
  if (seconds > 0.0) {
    bench.model().set_intent(from, way / seconds);
    if (!bench.run_for(seconds)) {
      return false;
    }
  }
  bench.model().set_intent(to, Eigen::Vector3d::Zero());
  return true;
}

// The largest distance of a series from its least-squares line.
double detrended_amplitude(const std::vector<double>& t, const std::vector<double>& y) {
  if (t.size() < 3) {
    return 0.0;
  }
  const auto n = static_cast<double>(t.size());
  double st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sy += y[i];
    stt += t[i] * t[i];
    sty += t[i] * y[i];
  }
  const double denominator = n * stt - st * st;
  const double slope = denominator != 0.0 ? (n * sty - st * sy) / denominator : 0.0;
  const double intercept = (sy - slope * st) / n;
  double amplitude = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    amplitude = std::max(amplitude, std::fabs(y[i] - (intercept + slope * t[i])));
  }
  return amplitude;
}

std::string safe_state_error(const WallBench& bench, const char* where) {
  return std::string("the cycle went to its safe state (") + control::safe_reason_name(bench.safe_reason()) + ") " + where;
}

// A contact's figures from the samples [from, held_until): the hand's intent reached its hold at
// `intent_stops_s`. The handle's depth is measured past the wall's plane (device z, + into the part).
void contact_figures(const std::vector<Sample>& s, std::size_t from, std::size_t held_until, double wall_z,
                     double intent_stops_s, WallRow& row) {
  std::size_t contact = from;
  while (contact < held_until && s[contact].handle_mm.z() >= wall_z) {
    ++contact;
  }
  if (contact == held_until) {
    row.error = "the hand never reached the face";
    return;
  }
  const auto depth = [&](std::size_t i) { return wall_z - s[i].handle_mm.z(); };
  const double t_contact = s[contact].t_s;
  // The first peak: where the handle first turns back (or the deepest in the first 100 ms).
  for (std::size_t i = contact; i < held_until && s[i].t_s <= t_contact + 0.1; ++i) {
    row.first_peak_mm = std::max(row.first_peak_mm, depth(i));
    if (i + 1 < held_until && depth(i + 1) < depth(i)) {
      break;
    }
  }
  for (std::size_t i = contact; i < held_until; ++i) {
    row.rebound_mm = std::max(row.rebound_mm, -depth(i));
  }
  // What oscillates 100 ms after contact (or after the hand stopped pushing in, if later): over the
  // next 200 ms (two periods of the hand ringing on the wall at 10 Hz, more at its stiffer), the
  // largest departure from the straight line through the depth, so that a slow settling (an
  // overdamped hand creeping in) is not counted as oscillation, and a ringing one is.
  const double t_from = std::max(t_contact, intent_stops_s) + 0.1;
  std::vector<double> t, d;
  for (std::size_t i = contact; i < held_until; ++i) {
    if (s[i].t_s >= t_from && s[i].t_s <= t_from + 0.2) {
      t.push_back(s[i].t_s);
      d.push_back(depth(i));
    }
  }
  const double left = detrended_amplitude(t, d);
  row.residual_fraction = row.first_peak_mm > 0.0 ? left / row.first_peak_mm : 0.0;
  row.stable = row.residual_fraction <= kStableFraction;
}

void run_tap(WallBench& bench, const WallCase& c, const Eigen::Vector3d& start, double wall_z, double push_depth_mm,
             WallRow& row) {
  const Eigen::Vector3d hold(start.x(), start.y(), wall_z - push_depth_mm);
  bench.model().reset_rendered_work();
  const std::size_t from = bench.samples().size();
  if (!move_intent(bench, start, hold, c.speed_device_mm_per_s)) {
    row.error = safe_state_error(bench, "while tapping");
    return;
  }
  const double intent_stops_s = bench.now_s();
  if (!bench.run_for(0.8)) {
    row.error = safe_state_error(bench, "while held against the face");
    return;
  }
  const std::size_t held_until = bench.samples().size();
  // Then away again at the same speed: the energy is counted over the whole contact.
  if (!move_intent(bench, hold, start, c.speed_device_mm_per_s) || !bench.run_for(0.2)) {
    row.error = safe_state_error(bench, "while leaving the face");
    return;
  }
  row.wall_energy_j = bench.model().rendered_work_j();
  row.passive = row.wall_energy_j <= kPassiveEnergyJ;
  contact_figures(bench.samples(), from, held_until, wall_z, intent_stops_s, row);
}

// The hand pulls along the face (+x) by ramping its intent until the pull the cycle renders against
// it (-x, beyond what it rendered when the ramp began) reaches `pull_n`, then holds; false on a safe
// state or when it never gets there in 2 s.
bool ramp_pull(WallBench& bench, const Eigen::Vector3d& from, double pull_n) {
  const double start_x = bench.samples().back().force_n.x();
  Eigen::Vector3d intent = from;
  for (int i = 0; i < 2000; ++i) {
    intent.x() += 0.01;  // 10 device mm/s
    bench.model().set_intent(intent, Eigen::Vector3d::Zero());
    if (!bench.step()) {
      return false;
    }
    if (start_x - bench.samples().back().force_n.x() >= pull_n) {
      return true;
    }
  }
  return false;
}

// The cycle ready and the force's ramp after the start waited out (the first half second), the
// hand still; false with row.error when not.
bool started(WallBench& bench, const control::ControllerConfig& config, WallRow& row) {
  if (!bench.ready()) {
    row.error = "the cycle is not ready (the tables' tool)";
    return false;
  }
  if (!bench.run_for(config.ramp_time_s + 0.1)) {
    row.error = safe_state_error(bench, "before the hand moved");
    return false;
  }
  return true;
}

// Dragged along the face (device +x) from `pressed`: the friction felt while the tool slides, in
// row.friction_ratio. False with row.error when it never slid or the cycle stopped.
bool drag_along_face(WallBench& bench, const WallCase& c, const Eigen::Vector3d& pressed, WallRow& row) {
  // Dragged along the face (device +x): the tool first sticks while the hand and the coupling stretch
  // (at 0.05 N per device mm and the relaxed hand, about 40 device mm of the hand's way), then slides.
  // The friction is measured over 0.6 s of sliding, from 0.4 s after it began, on the periods in
  // which the tool slid along the face.
  bench.model().set_intent(pressed, Eigen::Vector3d(std::min(c.speed_device_mm_per_s, 50.0), 0.0, 0.0));
  const auto slid = [&bench] {
    const std::vector<Sample>& s = bench.samples();
    const Eigen::Vector3d moved = s.back().tip_mm - s[s.size() - 2].tip_mm;
    return std::hypot(moved.x(), moved.y()) > 1e-7;
  };
  bool sliding = false;
  for (int period = 0; period < kMaxStickPeriods && !sliding; ++period) {
    if (!bench.step()) {
      row.error = safe_state_error(bench, "while dragged");
      return false;
    }
    sliding = slid();
  }
  if (!sliding) {
    row.error = "the tool never slid along the face while dragged";
    return false;
  }
  if (!bench.run_for(0.4)) {
    row.error = safe_state_error(bench, "while sliding");
    return false;
  }
  const std::size_t measured_from = bench.samples().size();
  if (!bench.run_for(0.6)) {
    row.error = safe_state_error(bench, "while sliding");
    return false;
  }
  // The force the hand felt: what the motors drove (after the link's delay), not the command.
  double tangential = 0.0, normal = 0.0;
  int slipping = 0;
  const std::vector<Sample>& s = bench.samples();
  for (std::size_t i = measured_from; i < s.size(); ++i) {
    const Eigen::Vector3d moved = s[i].tip_mm - s[i - 1].tip_mm;
    if (std::hypot(moved.x(), moved.y()) > 1e-7) {
      tangential -= s[i].applied_n.x();  // along the drag (+x), signed: the contact's sideways waver cancels
      normal += s[i].applied_n.z();
      ++slipping;
    }
  }
  if (slipping == 0 || !(normal > 0.0)) {
    row.error = "the tool never slid along the face while dragged";
    return false;
  }
  row.friction_ratio = tangential / normal;
  return true;
}

void run_slide(WallBench& bench, const WallCase& c, const Eigen::Vector3d& start, double wall_z, double push_depth_mm,
               WallRow& row) {
  // Pressed onto the face at 100 device mm/s and held: its figures as a slow tap's. From 50 device mm
  // (5 world mm) before the face's middle (the face is 160 device mm long), so that the drag and the
  // pull after it stay on the face.
  const Eigen::Vector3d above(start.x() - 50.0, start.y(), start.z());
  if (!move_intent(bench, start, above, 100.0) || !bench.run_for(0.2)) {
    row.error = safe_state_error(bench, "while moving over the face");
    return;
  }
  const Eigen::Vector3d pressed(above.x(), above.y(), wall_z - push_depth_mm);
  bench.model().reset_rendered_work();
  const std::size_t from = bench.samples().size();
  if (!move_intent(bench, above, pressed, 100.0)) {
    row.error = safe_state_error(bench, "while pressing on the face");
    return;
  }
  const double intent_stops_s = bench.now_s();
  if (!bench.run_for(0.8)) {
    row.error = safe_state_error(bench, "while pressed on the face");
    return;
  }
  row.wall_energy_j = bench.model().rendered_work_j();
  row.passive = row.wall_energy_j <= kPassiveEnergyJ;
  contact_figures(bench.samples(), from, bench.samples().size(), wall_z, intent_stops_s, row);
  if (!row.error.empty()) {
    return;
  }
  if (!drag_along_face(bench, c, pressed, row)) {
    return;
  }
  // Held inside the cone: the hand stops right over the tool (no pull left along the face), then
  // pulls along it, slowly, until the pull is half what the cone holds; the tool must not move.
  const double over_tool_x = motion::world_to_device(bench.frames(), bench.samples().back().tip_mm).x();
  const Eigen::Vector3d resting(over_tool_x, pressed.y(), pressed.z());
  bench.model().set_intent(resting, Eigen::Vector3d::Zero());
  if (!bench.run_for(0.4)) {
    row.error = safe_state_error(bench, "while resting on the face");
    return;
  }
  const double normal_n = std::max(bench.samples().back().force_n.z(), 0.0);
  const Eigen::Vector3d tip_before = bench.samples().back().tip_mm;
  if (c.friction > 0.0) {
    if (!ramp_pull(bench, resting, 0.5 * c.friction * normal_n) ||
        !bench.run_for(0.3)) {
      row.error = "held inside the cone: the pull never reached half of it, or the cycle stopped";
      return;
    }
    const Eigen::Vector3d moved = bench.samples().back().tip_mm - tip_before;
    row.stuck_slip_mm = std::hypot(moved.x(), moved.y());
  }
}

// A unit vector in the horizontal plane, `degrees` from +x towards +y.
Eigen::Vector3d heading_of(double degrees) {
  const double radians = degrees * 3.14159265358979323846 / 180.0;
  return {std::cos(radians), std::sin(radians), 0.0};
}

// The hand as it pushes on faster than the mill follows: its intent runs along `way` (a unit vector)
// at the case's speed from `start`, but never more than push / k (its arm's stiffness) ahead of the
// handle along it, so the arm's spring pulls with at most the push; held back, the intent rides along
// with the handle at its speed over the period, leaving the arm's damper nothing to add. A force
// source of at most the push, then: what the penalty must hold on its own (a real arm's damping would
// only help it).
void push_along(WallBench& bench, const Eigen::Vector3d& start, const Eigen::Vector3d& way, double scripted_s,
                double speed, double lead_mm, bool& pushing) {
  const double scripted = speed * scripted_s;
  const double handle = (bench.model().position_mm() - start).dot(way);
  if (scripted <= handle + lead_mm) {
    bench.model().set_intent(start + scripted * way, speed * way);
    return;
  }
  pushing = true;
  bench.model().set_intent(start + (handle + lead_mm) * way, bench.model().velocity_mm_per_s().dot(way) * way);
}

// Where the speed first peaked (an index into `speed`), on the speed averaged over
// kPeakSmoothingPeriods (the penalty acts on a velocity estimated from positions in whole micrometres,
// 1 mm/s a period, and the handle jitters with it by a few percent): once past half its steady value,
// the highest before it first falls back by more than kPeakDropFraction of the steady value; a speed
// that only rises to its steady value peaks where it first gets there.
std::size_t first_speed_peak(const std::vector<double>& speed, double steady, double& peak_speed) {
  std::vector<double> smooth(speed.size());
  double running = 0.0;
  for (std::size_t i = 0; i < speed.size(); ++i) {
    running += speed[i] - (i >= kPeakSmoothingPeriods ? speed[i - kPeakSmoothingPeriods] : 0.0);
    smooth[i] = running / static_cast<double>(std::min(i + 1, kPeakSmoothingPeriods));
  }
  std::size_t rising = 0;
  while (rising + 1 < smooth.size() && smooth[rising] < 0.5 * steady) {
    ++rising;
  }
  std::size_t peak = rising;
  bool fell_back = false;
  for (std::size_t i = rising; i < smooth.size() && !fell_back; ++i) {
    peak = smooth[i] > smooth[peak] ? i : peak;
    fell_back = smooth[i] < smooth[peak] - kPeakDropFraction * steady;
  }
  if (!fell_back) {
    peak = rising;
    while (peak + 1 < smooth.size() && smooth[peak] < steady) {
      ++peak;
    }
  }
  peak_speed = smooth[peak];
  return peak;
}

// The speed's figures from the samples [from, end): the handle's speed along `way` (a unit vector) a
// period at a time.
void speed_figures(const std::vector<Sample>& s, std::size_t from, const motion::MachineFrames& frames,
                   const Eigen::Vector3d& way, WallRow& row) {
  std::vector<double> t, speed;
  for (std::size_t i = from + 1; i < s.size(); ++i) {
    t.push_back(s[i].t_s);
    speed.push_back((s[i].handle_mm - s[i - 1].handle_mm).dot(way) / (s[i].t_s - s[i - 1].t_s));
  }
  if (t.size() < 2) {
    row.error = "the case ran no periods";
    return;
  }
  double sum = 0.0, lag = 0.0;
  int n = 0;
  row.steady_max_device_mm_per_s = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] > t.back() - kSteadyWindowS) {
      sum += speed[i];
      lag += (s[from + 1 + i].handle_mm - motion::world_to_device(frames, s[from + 1 + i].tip_mm)).dot(way);
      row.steady_max_device_mm_per_s = std::max(row.steady_max_device_mm_per_s, speed[i]);
      ++n;
    }
  }
  row.held_speed_device_mm_per_s = sum / n;
  row.lag_device_mm = lag / n;
  // Under the limit on average and all the time: a hand the cap's spring alone holds averages the
  // mill's speed itself, its mean over a window above or below with the swing's phase.
  row.held = row.held_speed_device_mm_per_s < row.limit_device_mm_per_s &&
             row.steady_max_device_mm_per_s < row.limit_device_mm_per_s;
  const std::size_t peak = first_speed_peak(speed, row.held_speed_device_mm_per_s, row.first_peak_device_mm_per_s);
  // What oscillates from 100 ms after it, over the next 200 ms, a period at a time (the jitter too):
  // the largest departure from the straight line through the speed (a slow settling is not an
  // oscillation), over the first peak.
  std::vector<double> window_t, window_speed;
  for (std::size_t i = peak; i < t.size(); ++i) {
    if (t[i] >= t[peak] + 0.1 && t[i] <= t[peak] + 0.3) {
      window_t.push_back(t[i]);
      window_speed.push_back(speed[i]);
    }
  }
  const double left = detrended_amplitude(window_t, window_speed);
  row.residual_fraction = row.first_peak_device_mm_per_s > 0.0 ? left / row.first_peak_device_mm_per_s : 0.0;
  row.stable = row.residual_fraction <= kStableFraction;
}

// A speed case's cycle: the rig's, its speed cap on (the mill's speed is the point here); the cap
// alone (previous) or with the penalty (new), nothing else of the wall's feel (no wall is touched).
// The virtual tool and the handle start in free space, 5 world mm above the top face (the part's
// highest) and 5 world mm before its middle: the hand's way along +x (at most 20 world mm, 10 s at
// twice the mill's speed) stays clear of the part and inside the device's reach.
control::ControllerConfig speed_config(const tables::PartTables& part, const WallCase& c, Eigen::Vector3d& start) {
  const Face face = top_face(part);
  control::ControllerConfig config = controller_config(false);
  config.haptic.coupling_n_per_device_mm = c.coupling_n_per_device_mm;
  config.feel = engine::WallFeel{};
  config.feel.transport_delay_s = c.transport_delay_s;
  if (c.rendering == WallRendering::New) {
    config.feel.speed_limiting = engine::SpeedLimiting::Penalty;
    config.feel.speed_penalty_slope_n_s_per_m = c.speed_penalty_slope_n_s_per_m;
  }
  config.home_tip_mm = Eigen::Vector3d(face.centre.x() - 5.0, face.centre.y(), face.top_z + config.standoff_mm + 5.0);
  config.start_held = false;
  start = motion::world_to_device(config.frames, config.home_tip_mm);
  return config;
}

WallRow run_speed_case(const tables::PartTables& part, const WallCase& c) {
  WallRow row;
  row.c = c;
  Eigen::Vector3d start;
  const control::ControllerConfig config = speed_config(part, c, start);
  const Eigen::Vector3d way = heading_of(c.heading_deg);
  row.limit_device_mm_per_s = mill_speed_device_mm_per_s(way);
  if (!(c.hand.stiffness_n_per_m > 0.0) || !(c.push_n > 0.0)) {
    row.error = "the hand has no stiffness or no push: it cannot push";
    return row;
  }
  const double lead_mm = 1e3 * c.push_n / c.hand.stiffness_n_per_m;
  WallBench bench(part, c, config, start);
  if (!started(bench, config, row)) {
    return row;
  }
  // Until kSpeedSettleS after the hand first pushes with all its push (the relaxed hand's arm takes
  // seconds to stretch that far), at most kMaxSpeedCaseS.
  const std::size_t from = bench.samples().size();
  const double began_s = bench.now_s();
  bool pushing = false;
  double pushing_since_s = std::numeric_limits<double>::infinity();
  while (bench.now_s() - began_s < kMaxSpeedCaseS && bench.now_s() < pushing_since_s + kSpeedSettleS) {
    push_along(bench, start, way, bench.now_s() - began_s, c.speed_device_mm_per_s, lead_mm, pushing);
    if (pushing && !std::isfinite(pushing_since_s)) {
      pushing_since_s = bench.now_s();
    }
    if (!bench.step()) {
      row.error = safe_state_error(bench, "while the hand pushed on");
      return row;
    }
  }
  speed_figures(bench.samples(), from, bench.frames(), way, row);
  return row;
}

// The hand lets go of the handle while pushing with the force limit against the lagging virtual tool:
// nothing holds the handle but the device's own mass and friction, and the coupling, stretched to the
// force limit along +x, pulls it back at once with all its force (no ramp). A damper rendered from a
// lagging velocity on that bare mass is where it rings first.
WallRow run_release_case(const tables::PartTables& part, const WallCase& c) {
  WallRow row;
  row.c = c;
  row.c.hand = stencil::sim::kNoHand;
  row.limit_device_mm_per_s = mill_speed_device_mm_per_s(Eigen::Vector3d::UnitX());
  Eigen::Vector3d start;
  control::ControllerConfig config = speed_config(part, c, start);
  const double stretch_device_mm = config.haptic.max_force_n / c.coupling_n_per_device_mm;
  config.home_tip_mm.x() += stretch_device_mm / config.frames.device_mm_per_world_mm;
  config.ramp_time_s = 0.0;
  WallBench bench(part, row.c, config, start);
  if (!bench.ready()) {
    row.error = "the cycle is not ready (the tables' tool)";
    return row;
  }
  if (!bench.run_for(kReleaseS)) {
    row.error = safe_state_error(bench, "while the handle was let go");
    return row;
  }
  speed_figures(bench.samples(), 0, bench.frames(), Eigen::Vector3d::UnitX(), row);
  return row;
}

}  // namespace

const char* name_of(WallRendering rendering) { return rendering == WallRendering::New ? "new" : "previous"; }
const char* name_of(WallTestKind test) {
  switch (test) {
    case WallTestKind::Slide:
      return "slide";
    case WallTestKind::Speed:
      return "speed";
    case WallTestKind::Release:
      return "release";
    case WallTestKind::Tap:
      break;
  }
  return "tap";
}

double mill_speed_device_mm_per_s(const Eigen::Vector3d& way) {
  const control::ControllerConfig config = controller_config(false);
  const double per_period = config.haptic.device_mm_per_world_mm / config.period_s;
  return engine::mill_speed_along(way, per_period * config.max_axis_move_mm, per_period * config.max_total_move_mm);
}

WallCase speed_test_case(const stencil::sim::HandParameters& hand, double coupling_n_per_device_mm,
                         WallRendering rendering, double speed_factor, double push_n, double heading_deg) {
  WallCase c;
  c.hand = hand;
  c.coupling_n_per_device_mm = coupling_n_per_device_mm;
  c.rendering = rendering;
  c.test = WallTestKind::Speed;
  c.heading_deg = heading_deg;
  c.speed_device_mm_per_s = speed_factor * mill_speed_device_mm_per_s(heading_of(heading_deg));
  c.push_n = push_n;
  c.transport_delay_s = kCanDelayS;
  return c;
}

engine::WallFeel new_wall_feel(double coupling_n_per_device_mm, double contact_stiffness_n_per_device_mm,
                               double friction) {
  engine::WallFeel feel;
  const double stiffness_n_per_m = 1e3 * (coupling_n_per_device_mm + contact_stiffness_n_per_device_mm);
  feel.damping_n_s_per_m = kDampingBaseNSPerM + kDampingPerStiffnessNSPerM * 1e-3 * stiffness_n_per_m;
  feel.passivity = true;
  feel.friction = friction;
  return feel;
}

WallRow run_wall_case(const tables::PartTables& part, const WallCase& c) {
  if (c.test == WallTestKind::Speed) {
    return run_speed_case(part, c);
  }
  if (c.test == WallTestKind::Release) {
    return run_release_case(part, c);
  }
  WallRow row;
  row.c = c;
  const Face face = top_face(part);
  control::ControllerConfig config = controller_config(false);
  // The wall's feel with the virtual tool free to follow the hand: at the mill's speed (1 world mm/s)
  // a tap at 200 device mm/s would be all the lagging tool's pull and none of the wall's.
  config.max_axis_move_mm = std::numeric_limits<double>::infinity();
  config.max_total_move_mm = std::numeric_limits<double>::infinity();
  config.haptic.coupling_n_per_device_mm = c.coupling_n_per_device_mm;
  config.feel = c.rendering == WallRendering::New
                    ? new_wall_feel(c.coupling_n_per_device_mm, config.contact.stiffness_n_per_device_mm,
                                    c.friction)
                    : engine::WallFeel{};
  config.feel.friction = c.friction;  // the case's: 0 for today's rendering, which has none
  config.feel.transport_delay_s = c.transport_delay_s;
  const Eigen::Vector3d start_world(face.centre.x(), face.centre.y(), face.top_z + config.standoff_mm + 1.0);
  config.home_tip_mm = start_world;
  config.start_held = false;
  const Eigen::Vector3d start = motion::world_to_device(config.frames, start_world);
  const double wall_z = motion::world_to_device(config.frames, Eigen::Vector3d(0.0, 0.0, face.top_z + config.standoff_mm)).z();
  // How far past the face the hand aims so that it pushes with push_n once there: its arm's stretch
  // plus the wall's own give (the coupling and the contact's stiffness, N per device mm).
  const double hand_n_per_mm = 1e-3 * c.hand.stiffness_n_per_m;
  const double wall_n_per_mm = c.coupling_n_per_device_mm + config.contact.stiffness_n_per_device_mm;
  if (!(hand_n_per_mm > 0.0)) {
    row.error = "the hand has no stiffness: it cannot push";
    return row;
  }
  const double push_depth_mm = c.push_n / hand_n_per_mm + c.push_n / wall_n_per_mm;
  WallBench bench(part, c, config, start);
  if (!started(bench, config, row)) {
    return row;
  }
  if (c.test == WallTestKind::Tap) {
    run_tap(bench, c, start, wall_z, push_depth_mm, row);
  } else {
    run_slide(bench, c, start, wall_z, push_depth_mm, row);
  }
  return row;
}

namespace {

std::string speed_row_json(const WallRow& row) {
  nlohmann::ordered_json j;
  j["hand"] = std::string(row.c.hand.name);
  j["coupling_n_per_device_mm"] = row.c.coupling_n_per_device_mm;
  j["rendering"] = name_of(row.c.rendering);
  j["test"] = name_of(row.c.test);
  if (row.c.test == WallTestKind::Speed) {  // a released handle has no hand to move or push it
    j["speed_device_mm_per_s"] = row.c.speed_device_mm_per_s;
    j["heading_deg"] = row.c.heading_deg;
    j["push_n"] = row.c.push_n;
  }
  j["transport_delay_s"] = row.c.transport_delay_s;
  j["virtual_tool_speed_limit"] = "on";
  j["speed_limiting"] = row.c.rendering == WallRendering::New ? "penalty" : "cap";
  j["limit_device_mm_per_s"] = row.limit_device_mm_per_s;
  j["held_speed_device_mm_per_s"] = row.held_speed_device_mm_per_s;
  j["steady_max_device_mm_per_s"] = row.steady_max_device_mm_per_s;
  j["first_peak_device_mm_per_s"] = row.first_peak_device_mm_per_s;
  j["lag_device_mm"] = row.lag_device_mm;
  j["residual_fraction"] = row.residual_fraction;
  j["held"] = row.held;
  j["stable"] = row.stable;
  if (!row.error.empty()) {
    j["error"] = row.error;
  }
  return j.dump();
}

std::string speed_row_text(const WallRow& row) {
  char line[256];
  std::snprintf(line, sizeof line, "%-8s %8.2f %-9s %-7s %10.2f %10.3f %10.3f %10.3f %9.3f %8.4f  %-4s %-6s %s",
                std::string(row.c.hand.name).c_str(), row.c.coupling_n_per_device_mm, name_of(row.c.rendering),
                name_of(row.c.test), row.limit_device_mm_per_s, row.held_speed_device_mm_per_s,
                row.steady_max_device_mm_per_s, row.first_peak_device_mm_per_s, row.lag_device_mm,
                row.residual_fraction, row.held ? "yes" : "NO", row.stable ? "yes" : "NO",
                row.error.empty() ? "" : ("error: " + row.error).c_str());
  return line;
}

}  // namespace

std::string speed_table_header() {
  return "hand     coupling rendering test    limit_mm/s  held_mm/s   max_mm/s  peak_mm/s    lag_mm residual  held stable";
}

std::string wall_row_json(const WallRow& row) {
  if (row.c.test == WallTestKind::Speed || row.c.test == WallTestKind::Release) {
    return speed_row_json(row);
  }
  nlohmann::ordered_json j;
  j["hand"] = std::string(row.c.hand.name);
  j["coupling_n_per_device_mm"] = row.c.coupling_n_per_device_mm;
  j["rendering"] = name_of(row.c.rendering);
  j["test"] = name_of(row.c.test);
  j["speed_device_mm_per_s"] = row.c.speed_device_mm_per_s;
  j["push_n"] = row.c.push_n;
  j["transport_delay_s"] = row.c.transport_delay_s;
  j["friction"] = row.c.friction;
  j["virtual_tool_speed_limit"] = "off";
  j["first_peak_mm"] = row.first_peak_mm;
  j["rebound_mm"] = row.rebound_mm;
  j["residual_fraction"] = row.residual_fraction;
  j["wall_energy_j"] = row.wall_energy_j;
  j["stable"] = row.stable;
  j["passive"] = row.passive;
  if (row.c.test == WallTestKind::Slide) {
    j["friction_ratio"] = row.friction_ratio;
    j["stuck_slip_mm"] = row.stuck_slip_mm;
  }
  if (!row.error.empty()) {
    j["error"] = row.error;
  }
  return j.dump();
}

std::string wall_table_header() {
  return "hand     coupling rendering test   first_peak_mm rebound_mm residual  wall_energy_j stable passive friction_ratio stuck_slip_mm";
}

std::string wall_row_text(const WallRow& row) {
  if (row.c.test == WallTestKind::Speed || row.c.test == WallTestKind::Release) {
    return speed_row_text(row);
  }
  char line[256];
  if (!row.error.empty()) {
    std::snprintf(line, sizeof line, "%-8s %8.2f %-9s %-5s  error: %s", std::string(row.c.hand.name).c_str(),
                  row.c.coupling_n_per_device_mm, name_of(row.c.rendering), name_of(row.c.test), row.error.c_str());
    return line;
  }
  char friction[64] = "";
  if (row.c.test == WallTestKind::Slide) {
    std::snprintf(friction, sizeof friction, "%14.3f %13.6f", row.friction_ratio, row.stuck_slip_mm);
  }
  std::snprintf(line, sizeof line, "%-8s %8.2f %-9s %-5s  %13.4f %10.4f %8.4f  %13.3e %-6s %-7s %s",
                std::string(row.c.hand.name).c_str(), row.c.coupling_n_per_device_mm, name_of(row.c.rendering),
                name_of(row.c.test), row.first_peak_mm, row.rebound_mm, row.residual_fraction, row.wall_energy_j,
                row.stable ? "yes" : "NO", row.passive ? "yes" : "NO", friction);
  return line;
}

}  // namespace stencil::board::sim
