// CppUTest printers for the SocketCAN backend's enums.
#pragma once

#include <CppUTest/SimpleString.h>

#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_codec.hpp"

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

}  // namespace stencil::hal::socketcan
