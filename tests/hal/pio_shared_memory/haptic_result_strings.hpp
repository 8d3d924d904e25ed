// CppUTest printers for the hal::HapticDevice status enums, so a failed CHECK_EQUAL names the values.
// Shared by the haptic tests of both backends and of the simulated device.
#pragma once

#include <CppUTest/SimpleString.h>

#include "hal/haptic_device.hpp"

namespace stencil::hal {

inline SimpleString StringFrom(ReadStatus status) {
  constexpr const char* kNames[] = {"Fresh", "Stale", "Rejected", "Fault"};
  return kNames[static_cast<int>(status)];
}
inline SimpleString StringFrom(WriteStatus status) {
  constexpr const char* kNames[] = {"Written", "Clamped", "Rejected", "Fault", "Held"};
  return kNames[static_cast<int>(status)];
}
inline SimpleString StringFrom(HapticFault fault) {
  constexpr const char* kNames[] = {"None",          "NotOpen",          "SampleBusy",
                                    "SampleOutOfRange", "SampleNotFinite", "BadFrame",      "CommandNotFinite",
                                    "DeviceHeartbeatLost", "TransportError", "TransportFull",
                                    "HostWatchdogTripped"};
  return kNames[static_cast<int>(fault)];
}
inline SimpleString StringFrom(HapticLinkState state) {
  constexpr const char* kNames[] = {"Closed", "WaitingForDevice", "Connected", "Disconnected"};
  return kNames[static_cast<int>(state)];
}

}  // namespace stencil::hal
