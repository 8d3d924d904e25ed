// FakeHapticDevice: a HapticDevice whose every read is scripted by the test and whose every write
// is recorded, for tests of the cycle without a device, a window or a bus.
#pragma once

#include <cstdint>
#include <vector>

#include "hal/haptic_device.hpp"

namespace stencil::test {

class FakeHapticDevice final : public hal::HapticDevice {
 public:
  // What the next reads give: a fresh sample at `position_mm` (its counter moves by one per read)
  // unless the test set another outcome.
  void hold_at(double x, double y, double z) {
    sample_.position_mm[0] = x;
    sample_.position_mm[1] = y;
    sample_.position_mm[2] = z;
  }
  void give(hal::ReadStatus status, hal::HapticFault reason = hal::HapticFault::None) {
    status_ = status;
    reason_ = reason;
    if (status == hal::ReadStatus::Fault) {
      latched_ = reason;
    }
  }
  void fail_writes(bool fail) { fail_writes_ = fail; }
  void set_status_bits(std::uint32_t bits) { sample_.status_bits = bits; }
  void connect(bool connected) { connected_ = connected; }

  hal::ReadResult read_sample(hal::MonotonicNs, hal::HapticSample& out) override {
    ++reads_;
    if (status_ != hal::ReadStatus::Fresh) {
      return {status_, reason_};
    }
    ++sample_.sample_counter;
    out = sample_;
    return {hal::ReadStatus::Fresh, hal::HapticFault::None};
  }

  hal::WriteResult write_command(const hal::HapticCommand& command) override {
    commands_.push_back(command);
    if (fail_writes_) {
      latched_ = hal::HapticFault::TransportError;
      return {hal::WriteStatus::Fault, hal::HapticFault::TransportError};
    }
    return {hal::WriteStatus::Written, hal::HapticFault::None};
  }

  [[nodiscard]] hal::HapticLinkState link_state() const override {
    return connected_ ? hal::HapticLinkState::Connected : hal::HapticLinkState::Disconnected;
  }
  [[nodiscard]] hal::HapticFault latched_fault() const override { return latched_; }
  void clear_fault() override { latched_ = hal::HapticFault::None; }
  [[nodiscard]] hal::HapticCounters counters() const override { return {}; }

  [[nodiscard]] const std::vector<hal::HapticCommand>& commands() const { return commands_; }
  [[nodiscard]] const hal::HapticCommand& last_command() const { return commands_.back(); }
  [[nodiscard]] std::uint64_t reads() const { return reads_; }

 private:
  hal::HapticSample sample_{{0.0, 0.0, 0.0}, {0.0, 0.0}, 0, 0, 0};
  hal::ReadStatus status_ = hal::ReadStatus::Fresh;
  hal::HapticFault reason_ = hal::HapticFault::None;
  hal::HapticFault latched_ = hal::HapticFault::None;
  bool fail_writes_ = false;
  bool connected_ = true;
  std::vector<hal::HapticCommand> commands_;
  std::uint64_t reads_ = 0;
};

}  // namespace stencil::test
