// CppUTest printers for the SocketCAN backend's enums.
#pragma once

#include <CppUTest/SimpleString.h>

#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/can_error_frames.hpp"

namespace stencil::hal::socketcan {

inline SimpleString StringFrom(FrameRejection rejection) {
  constexpr const char* kNames[] = {"None",           "WrongDlc",     "UnknownId", "OutOfRange",
                                    "ReservedNotZero", "HalvesDisagree", "UnpairedHalf", "WrongSize"};
  return kNames[static_cast<int>(rejection)];
}
inline SimpleString StringFrom(FrameEffect effect) {
  constexpr const char* kNames[] = {"HalfHeld", "Completed", "Status", "Rejected"};
  return kNames[static_cast<int>(effect)];
}
inline SimpleString StringFrom(TransferStatus status) {
  constexpr const char* kNames[] = {"Done", "WouldBlock", "WrongSize", "Closed", "Error"};
  return kNames[static_cast<int>(status)];
}

inline SimpleString StringFrom(CanBusError error) {
  constexpr const char* kNames[] = {"None",         "BusOff",       "Restarted",         "NoAcknowledge",
                                    "TransmitTimeout", "ControllerOverflow", "ErrorPassive", "ErrorWarning",
                                    "ControllerProblem", "BackToErrorActive", "Other"};
  static_assert(sizeof kNames / sizeof kNames[0] == kCanBusErrorKinds);
  return kNames[static_cast<int>(error)];
}

}  // namespace stencil::hal::socketcan
