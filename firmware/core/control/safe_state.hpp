// Why the cycle is in its safe state (zero force, machine stopped): the latched reason, as data.
#pragma once

#include <cstdint>

namespace stencil::control {

enum class SafeReason : std::uint8_t {
  None,                // not in the safe state
  DeviceStale,         // no fresh device sample for more than the allowed periods
  DeviceFault,         // the haptic link latched a fault (disconnected, transport error)
  PoseNotFinite,       // a device sample with a NaN or infinity
  PoseOutOfWorkspace,  // a device sample outside the device's reach
  PoseJump,            // a sample farther from the last than the device can move in the time between
  MachineFault,        // the machine side reported a fault, or fell behind the cycle
  OverrunStorm,        // more consecutive overruns than allowed
  JournalFull,         // the journal ring was full: the record would lose a sample
  JournalFailed,       // the journal file could not be written (disk full, I/O error)
  EngineFault,         // the engine refused its inputs or found the tables damaged
  Stopped,             // a stop command (SIGINT/SIGTERM, the terminal, the display)
};

// The reasons the device's own samples (or their absence) give: what a replay of the samples
// reproduces by itself.
[[nodiscard]] constexpr bool is_device_reason(SafeReason reason) {
  return reason == SafeReason::DeviceStale || reason == SafeReason::DeviceFault || reason == SafeReason::PoseNotFinite ||
         reason == SafeReason::PoseOutOfWorkspace || reason == SafeReason::PoseJump;
}

// Whether a byte read back (a journal's record) names a SafeReason: the last one is Stopped.
[[nodiscard]] constexpr bool is_safe_reason_byte(std::uint8_t value) {
  return value <= static_cast<std::uint8_t>(SafeReason::Stopped);
}

// A short fixed name, for reports and logs ("device_stale", ...).
[[nodiscard]] const char* safe_reason_name(SafeReason reason);

}  // namespace stencil::control
