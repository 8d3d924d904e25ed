// Naming the CAN controller's error frames, and which of them stop the haptic link.
#include "hal/socketcan/can_error_frames.hpp"

namespace stencil::hal::socketcan {

CanBusError classify_error_frame(const can_frame& frame) {
  if (!is_error_frame(frame)) return CanBusError::None;
  const canid_t classes = frame.can_id & CAN_ERR_MASK;
  if ((classes & CAN_ERR_BUSOFF) != 0U) return CanBusError::BusOff;
  if ((classes & CAN_ERR_TX_TIMEOUT) != 0U) return CanBusError::TransmitTimeout;
  if ((classes & CAN_ERR_ACK) != 0U) return CanBusError::NoAcknowledge;
  if ((classes & CAN_ERR_CRTL) != 0U) {
    const std::uint8_t detail = frame.data[1];
    if ((detail & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0U) return CanBusError::ControllerOverflow;
    if ((detail & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0U) return CanBusError::ErrorPassive;
    if ((detail & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0U) return CanBusError::ErrorWarning;
    if (detail == CAN_ERR_CRTL_ACTIVE) return CanBusError::BackToErrorActive;
    return CanBusError::ControllerProblem;
  }
  if ((classes & CAN_ERR_RESTARTED) != 0U) return CanBusError::Restarted;
  return CanBusError::Other;
}

const char* can_bus_error_name(CanBusError error) {
  switch (error) {
    case CanBusError::None: return "none";
    case CanBusError::BusOff: return "bus-off";
    case CanBusError::Restarted: return "controller restarted after a bus-off";
    case CanBusError::NoAcknowledge: return "no acknowledge: no other node on the bus";
    case CanBusError::TransmitTimeout: return "transmit timeout";
    case CanBusError::ControllerOverflow: return "controller problem: frames lost to a full controller buffer";
    case CanBusError::ErrorPassive: return "controller problem: error passive";
    case CanBusError::ErrorWarning: return "controller problem: error warning";
    case CanBusError::ControllerProblem: return "controller problem";
    case CanBusError::BackToErrorActive: return "controller back to error active";
    case CanBusError::Other: return "bus error";
  }
  return "unknown";
}

can_frame make_error_frame(can_err_mask_t classes, std::uint8_t controller_detail) {
  can_frame frame{};
  frame.can_id = CAN_ERR_FLAG | (classes & CAN_ERR_MASK);
  frame.len = CAN_ERR_DLC;
  frame.data[1] = controller_detail;
  return frame;
}

}  // namespace stencil::hal::socketcan
