// linuxcncrsh's replies, parsed (allocation-free; fuzzed). The protocol is lines of words separated
// by spaces (linuxcncrsh(1)); what this project relies on, checked against LinuxCNC 2.9's
// linuxcncrsh in sim/linuxcnc_mill/ (tests/hal/linuxcnc):
//  - "HELLO ACK <server> <version>" or "HELLO NAK" after hello;
//  - with verbose on, "SET <NAME> ACK" or "SET <NAME> NAK" after every set, ended "\n\r" (the "\r"
//    starts the next line: TcpLineChannel drops it); a set is answered once LinuxCNC's task has
//    received it (about 100 ms: linuxcncrsh polls every 0.1 s);
//  - "<NAME> <value>..." after get: "ESTOP ON", "MACHINE OFF", "MODE MDI", "PROGRAM_STATUS IDLE",
//    "JOINT_HOMED YES YES YES NO NO NO", "ABS_ACT_POS 1.000000 2.000000 3.000000 0.000000 ...";
//  - "ERROR OK" when LinuxCNC has no error to report, else "ERROR <its own words>" (one each get,
//    oldest first). An MDI line LinuxCNC refuses is still "SET MDI ACK": the refusal comes as an error.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace stencil::hal::linuxcnc {

enum class SetReply : unsigned char { Ack, Nak, Other };

// "SET <name> ACK" / "SET <name> NAK" (name in capitals, as linuxcncrsh answers); anything else Other.
[[nodiscard]] SetReply set_reply(std::string_view line, std::string_view name);

// "HELLO ACK ..." : true; "HELLO NAK" or anything else: false.
[[nodiscard]] bool hello_accepted(std::string_view line);

// The value of a get's one-word answer: value_of("ESTOP ON", "ESTOP") is "ON"; empty when the line
// is not `key` followed by exactly one word.
[[nodiscard]] std::string_view value_of(std::string_view line, std::string_view key);

// The first three numbers after `key` ("ABS_ACT_POS", "ABS_CMD_POS", "JOINT_POS"): false unless the
// line is key and at least three finite numbers (plain decimals, as LinuxCNC prints them).
[[nodiscard]] bool parse_xyz(std::string_view line, std::string_view key, std::array<double, 3>& xyz);

// "JOINT_HOMED YES YES NO ...": the first three joints; false unless each is YES or NO.
[[nodiscard]] bool parse_joints_homed(std::string_view line, std::array<bool, 3>& homed);

enum class ErrorReply : unsigned char { None, Error, Other };

// "ERROR OK": None; "ERROR <text>": Error with `text` LinuxCNC's words; anything else Other.
[[nodiscard]] ErrorReply parse_error(std::string_view line, std::string_view& text);

}  // namespace stencil::hal::linuxcnc
