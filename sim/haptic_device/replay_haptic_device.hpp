// ReplayHapticDevice: the device as a journal recorded it. Each cycle it gives back exactly the read
// the recorded cycle had (the sample, or the stale read, the refusal or the fault), so the cycle sees
// the same inputs bit for bit whatever transport the job ran over; its commands are taken and kept.
#pragma once

#include "firmware/core/control/cycle_messages.hpp"
#include "hal/haptic_device.hpp"

namespace stencil::sim {

class ReplayHapticDevice final : public hal::HapticDevice {
 public:
  // The recorded cycle whose read the next read_sample() gives.
  void set(const control::JournalRecord& record) { record_ = record; }
  [[nodiscard]] const hal::HapticCommand& rendered() const { return rendered_; }

  hal::ReadResult read_sample(hal::MonotonicNs, hal::HapticSample& out) override {
    if (record_.read_status == hal::ReadStatus::Fresh) {
      out = {{record_.device_mm[0], record_.device_mm[1], record_.device_mm[2]},
             {record_.angles_rad[0], record_.angles_rad[1]},
             record_.sample_counter,
             record_.status_bits,
             record_.sample_counter};
    }
    if (record_.read_status == hal::ReadStatus::Fault && latched_ == hal::HapticFault::None) {
      latched_ = record_.read_reason;
    }
    return {record_.read_status, record_.read_reason};
  }

  hal::WriteResult write_command(const hal::HapticCommand& command) override {
    rendered_ = command;
    return {hal::WriteStatus::Written, hal::HapticFault::None};
  }

  [[nodiscard]] hal::HapticLinkState link_state() const override { return hal::HapticLinkState::Connected; }
  [[nodiscard]] hal::HapticFault latched_fault() const override { return latched_; }
  void clear_fault() override { latched_ = hal::HapticFault::None; }
  [[nodiscard]] hal::HapticCounters counters() const override { return {}; }

 private:
  control::JournalRecord record_{};
  hal::HapticCommand rendered_{{0.0, 0.0, 0.0}, {0.0, 0.0}, 0, false};
  hal::HapticFault latched_ = hal::HapticFault::None;
};

}  // namespace stencil::sim
