// The device controller's side of the shared window: pose writes, command reads and the device's own
// range check of a command.
#include "hal/pio_shared_memory/pio_device_side.hpp"

#include "hal/pio_shared_memory/seqlock.hpp"

namespace stencil::hal::pio_shared_memory {

void PioDeviceSide::initialise_header() {
  store_word(window_.header.layout_version, kLayoutVersion);
  store_word(window_.header.window_bytes, static_cast<std::uint32_t>(kWindowBytes));
  std::atomic_thread_fence(std::memory_order_release);
  store_word(window_.header.magic, kWindowMagic);  // last: a host that sees the magic sees the rest
}

void PioDeviceSide::publish_pose(const PoseWords& pose) {
  seqlock_write(window_.pose, pose);
  ++counters_.poses_written;
}

bool command_within_device_limits(const CommandWords& command) {
  // Each square is at most 2^62 (of -2^31) and fits a signed 64 bits, but two of them do not: the
  // sums are unsigned, where three of 2^62 fit.
  const auto square = [](std::int32_t word) { return static_cast<std::uint64_t>(std::int64_t{word} * word); };
  std::uint64_t force_squared = 0;
  for (const std::int32_t force : command.force_mn) force_squared += square(force);
  std::uint64_t torque_squared = 0;
  for (const std::int32_t torque : command.torque_mnmm) torque_squared += square(torque);
  return force_squared <= square(kForceLimitMn) && torque_squared <= square(kTorqueLimitMnmm) &&
         (command.flags & ~kCommandEnableBit) == 0U;
}

CommandReadStatus PioDeviceSide::read_command(CommandWords& out) {
  CommandWords words{};
  const SeqlockRead read = seqlock_read(window_.command, words);
  counters_.torn_read_retries += static_cast<std::uint64_t>(read.retries);
  if (!read.consistent) {
    ++counters_.busy_reads;
    return CommandReadStatus::Busy;
  }
  if (read.sequence == last_command_sequence_) return CommandReadStatus::Unchanged;
  last_command_sequence_ = read.sequence;
  if (!command_within_device_limits(words)) {
    ++counters_.commands_out_of_range;
    return CommandReadStatus::OutOfRange;
  }
  out = words;
  ++counters_.commands_accepted;
  return CommandReadStatus::New;
}

}  // namespace stencil::hal::pio_shared_memory
