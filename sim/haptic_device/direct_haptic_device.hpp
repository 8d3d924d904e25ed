// DirectHapticDevice: the simulated device reached in-process, with no window or bus between (the
// host simulation's `--haptic-transport direct`): the simulation publishes the handle's pose, the
// cycle reads it and writes a command, which the backend clamps as the real ones do. Positions come
// in whole micrometres and angles in whole microradians, as the PIO window's words carry them (the
// CAN frames carry micrometres too), so that what the cycle sees, and the journal keeps, is what a
// real device's wire would give.
#pragma once

#include <cmath>

#include "hal/haptic_device.hpp"
#include "hal/haptic_range_checks.hpp"

namespace stencil::sim {

class DirectHapticDevice final : public hal::HapticDevice {
 public:
  explicit DirectHapticDevice(const hal::HapticRange& range) : range_(range) {}

  // The simulation's side: the handle's new pose (its counter moved), and the command the device
  // would render now (zero until the first write, and while enable is off).
  void publish(const hal::HapticSample& sample) {
    pending_ = sample;
    for (double& v : pending_.position_mm) {
      v = wire_rounded(v, 1e3, 1e-3);
    }
    for (double& v : pending_.angles_rad) {
      v = wire_rounded(v, 1e6, 1e-6);
    }
    ++published_;
  }
  [[nodiscard]] const hal::HapticCommand& rendered() const { return rendered_; }

  hal::ReadResult read_sample(hal::MonotonicNs, hal::HapticSample& out) override {
    if (published_ == consumed_) {
      ++counters_.stale_reads;
      return {hal::ReadStatus::Stale, hal::HapticFault::None};
    }
    consumed_ = published_;
    if (!hal::sample_finite(pending_)) {
      ++counters_.samples_out_of_range;
      return {hal::ReadStatus::Rejected, hal::HapticFault::SampleNotFinite};
    }
    if (!hal::sample_in_range(pending_, range_)) {
      ++counters_.samples_out_of_range;
      return {hal::ReadStatus::Rejected, hal::HapticFault::SampleOutOfRange};
    }
    ++counters_.samples_accepted;
    out = pending_;
    return {hal::ReadStatus::Fresh, hal::HapticFault::None};
  }

  hal::WriteResult write_command(const hal::HapticCommand& command) override {
    const hal::ClampedCommand clamped = hal::clamp_command(command, range_.force_limit_n, range_.torque_limit_nmm);
    const bool enable = command.enable && clamped.finite;
    rendered_ = {{enable ? clamped.force_n[0] : 0.0, enable ? clamped.force_n[1] : 0.0, enable ? clamped.force_n[2] : 0.0},
                 {enable ? clamped.torque_nmm[0] : 0.0, enable ? clamped.torque_nmm[1] : 0.0},
                 command.cycle_counter,
                 enable};
    return hal::write_outcome(clamped, counters_);
  }

  [[nodiscard]] hal::HapticLinkState link_state() const override { return hal::HapticLinkState::Connected; }
  [[nodiscard]] hal::HapticFault latched_fault() const override { return hal::HapticFault::None; }
  void clear_fault() override {}
  [[nodiscard]] hal::HapticCounters counters() const override { return counters_; }

 private:
  // As the PIO window's decoder makes it (a whole number of units times the unit); a value no wire
  // could carry (not finite, or beyond 2^31 units) is left as it is for the range checks to refuse.
  static double wire_rounded(double value, double units_per_value, double value_per_unit) {
    const double units = std::round(value * units_per_value);
    return std::fabs(units) < 2147483647.0 ? units * value_per_unit : value;
  }

  hal::HapticRange range_;
  hal::HapticSample pending_{};
  std::uint64_t published_ = 0;
  std::uint64_t consumed_ = 0;
  hal::HapticCommand rendered_{{0.0, 0.0, 0.0}, {0.0, 0.0}, 0, false};
  hal::HapticCounters counters_{};
};

}  // namespace stencil::sim
