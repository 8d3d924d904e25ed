// Names of the safe-state reasons.
#include "firmware/core/control/safe_state.hpp"

namespace stencil::control {

const char* safe_reason_name(SafeReason reason) {
  switch (reason) {
    case SafeReason::None:
      return "none";
    case SafeReason::DeviceStale:
      return "device_stale";
    case SafeReason::DeviceFault:
      return "device_fault";
    case SafeReason::PoseNotFinite:
      return "pose_not_finite";
    case SafeReason::PoseOutOfWorkspace:
      return "pose_out_of_workspace";
    case SafeReason::PoseJump:
      return "pose_jump";
    case SafeReason::MachineFault:
      return "machine_fault";
    case SafeReason::OverrunStorm:
      return "overrun_storm";
    case SafeReason::JournalFull:
      return "journal_full";
    case SafeReason::JournalFailed:
      return "journal_failed";
    case SafeReason::EngineFault:
      return "engine_fault";
    case SafeReason::Stopped:
      return "stopped";
  }
  return "unknown";
}

}  // namespace stencil::control
