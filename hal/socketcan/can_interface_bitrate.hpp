// The bitrate a CAN interface runs at, read from the kernel over rtnetlink (RTM_GETLINK: IFLA_LINKINFO
// -> IFLA_INFO_DATA -> IFLA_CAN_BITTIMING, struct can_bittiming), and the check made when the haptic
// link is opened: a bus too slow for a period's frames (can_bus_load.hpp) is refused. Init-time only
// (a socket, system calls, allocation): never called from the cycle. Raw rtnetlink rather than
// libsocketcan's can_get_bittiming() or libmnl: one request and a walk of one answer, not worth a new
// dependency on every machine that builds the rig.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace stencil::hal::socketcan {

enum class BitrateReading : std::uint8_t {
  Known,        // bitrate_bps is the interface's bitrate
  NoBitTiming,  // the interface has none to report: vcan, not a CAN interface, or no bitrate set yet
  Unreadable,   // the kernel could not be asked, or its answer was an error or not understood
};

struct InterfaceBitrate {
  BitrateReading reading;
  std::uint64_t bitrate_bps;  // when Known
  std::string detail;         // why not Known, in words ("a link of kind vcan has no bit timing")
};

// One rtnetlink answer to RTM_GETLINK (pure: what read_can_bitrate() parses, and what tests feed).
[[nodiscard]] InterfaceBitrate parse_link_bitrate(const void* answer, std::size_t length);

// Asks the kernel about `interface` (e.g. "can0"). Waits at most a second for the answer.
[[nodiscard]] InterfaceBitrate read_can_bitrate(const std::string& interface);

// The verdict on `bitrate` for the haptic frame set. False when the bitrate is known and too slow:
// `error` names the interface, its bitrate and the bitrate needed. True otherwise, with `note` saying
// the load at that bitrate, or that the bitrate could not be checked and why (vcan, unreadable): such
// an interface is accepted, since a vcan carries any load and a bus the kernel will not describe is
// the operator's to vouch for.
[[nodiscard]] bool check_can_bitrate(const std::string& interface, const InterfaceBitrate& bitrate, std::string& note,
                                     std::string& error);

// read_can_bitrate() and then the verdict.
[[nodiscard]] bool check_can_bitrate(const std::string& interface, std::string& note, std::string& error);

}  // namespace stencil::hal::socketcan
