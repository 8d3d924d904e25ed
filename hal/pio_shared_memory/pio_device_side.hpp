// PioDeviceSide: the device controller's side of the shared window (writes poses, reads commands),
// as the real controller must do it; the simulated device (sim/haptic_device) uses it as is.
// Real-time core: loads and stores of a mapped window only.
#pragma once

#include <cstdint>

#include "hal/pio_shared_memory/shared_window_layout.hpp"

namespace stencil::hal::pio_shared_memory {

enum class CommandReadStatus : std::uint8_t {
  New,         // a command the host wrote since the last read, within the device's limits
  Unchanged,   // the host has not written since the last read (or never wrote)
  Busy,        // the host was mid-write on every attempt: try again next device cycle
  OutOfRange,  // a new command beyond kForceLimitMn / kTorqueLimitMnmm or with unknown flag bits:
               // refused, the device must drive zero
};

struct DeviceSideCounters {
  std::uint64_t poses_written;
  std::uint64_t commands_accepted;
  std::uint64_t commands_out_of_range;
  std::uint64_t torn_read_retries;
  std::uint64_t busy_reads;
};

class PioDeviceSide {
 public:
  // The window must outlive this object.
  explicit PioDeviceSide(SharedWindow& window) : window_(window) {}

  // Writes the header words (magic, version, size): what the controller does once at power-up,
  // before its first pose. Init-time.
  void initialise_header();

  // One seqlock write of the pose block. Real-time safe.
  void publish_pose(const PoseWords& pose);

  // One bounded seqlock read of the command block; `out` is written only when New. Real-time safe.
  [[nodiscard]] CommandReadStatus read_command(CommandWords& out);

  [[nodiscard]] const DeviceSideCounters& counters() const { return counters_; }

 private:
  SharedWindow& window_;
  std::uint32_t last_command_sequence_ = 0;
  DeviceSideCounters counters_{};
};

// The device's own check of a command (whatever the host claims to have clamped).
[[nodiscard]] bool command_within_device_limits(const CommandWords& command);

}  // namespace stencil::hal::pio_shared_memory
