// Error frames: what the CAN controller's driver reports about the bus (linux/can/error.h), which
// classes the host's socket subscribes to (CAN_RAW_ERR_FILTER), what each is called, and which of
// them stop the haptic link. Real-time core.
#pragma once

#include <linux/can.h>
#include <linux/can/error.h>

#include <cstdint>

namespace stencil::hal::socketcan {

enum class CanBusError : std::uint8_t {
  None,                // not an error frame
  BusOff,              // CAN_ERR_BUSOFF: the controller left the bus (its transmit error count passed 255)
  Restarted,           // CAN_ERR_RESTARTED: it came back after a bus-off; frames were lost meanwhile
  NoAcknowledge,       // CAN_ERR_ACK: no node acknowledged our frame: the device is not on the bus
  TransmitTimeout,     // CAN_ERR_TX_TIMEOUT: a frame could not be sent in time
  ControllerOverflow,  // CAN_ERR_CRTL, RX/TX overflow: the controller's buffer was full and frames were lost
  ErrorPassive,        // CAN_ERR_CRTL, RX/TX passive: error counts past 127, the step before bus-off
  ErrorWarning,        // CAN_ERR_CRTL, RX/TX warning: error counts past 96, errors far above a sound bus
  ControllerProblem,   // CAN_ERR_CRTL, unspecified
  BackToErrorActive,   // CAN_ERR_CRTL with CAN_ERR_CRTL_ACTIVE alone: recovered; no fault
  Other,               // any other class (single bus errors, lost arbitration, transceiver): no fault
};
inline constexpr int kCanBusErrorKinds = 11;

// The classes the host subscribes to: each means the link lost or is about to lose frames. Single bus
// errors (CAN_ERR_BUSERROR, CAN_ERR_PROT) are not subscribed: the controller retransmits the frame
// itself, and errors that keep coming raise its error counts into the CRTL warning and passive
// reports and finally bus-off, all subscribed; a noisy bus with bus-error reporting on would otherwise
// fill the socket with error frames ahead of the poses. An ACK error comes with CAN_ERR_BUSERROR set,
// but the filter takes a frame that has any subscribed class.
inline constexpr can_err_mask_t kSubscribedErrorClasses =
    CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_ACK | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;

[[nodiscard]] constexpr bool is_error_frame(const can_frame& frame) { return (frame.can_id & CAN_ERR_FLAG) != 0U; }

// What an error frame says, the gravest first when it says several things; None for a data frame.
[[nodiscard]] CanBusError classify_error_frame(const can_frame& frame);

// True when the haptic link must stop: every class but recovery and single bus errors.
[[nodiscard]] constexpr bool stops_the_link(CanBusError error) {
  return error != CanBusError::None && error != CanBusError::BackToErrorActive && error != CanBusError::Other;
}

// "bus-off", "controller problem: error passive", ... (static strings).
[[nodiscard]] const char* can_bus_error_name(CanBusError error);

// An error frame as a driver sends it: these classes, the controller's detail (CAN_ERR_CRTL_*) in
// data[1]. For the simulated bus and tests.
[[nodiscard]] can_frame make_error_frame(can_err_mask_t classes, std::uint8_t controller_detail = 0);

}  // namespace stencil::hal::socketcan
