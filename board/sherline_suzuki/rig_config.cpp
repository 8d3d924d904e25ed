#include "board/sherline_suzuki/rig_config.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>

#include <cmath>
#include <cstdio>
#include <map>

// toml++ header-only, without exceptions: a parse error is a value (its description and line).
#define TOML_EXCEPTIONS 0
#include <toml++/toml.h>

namespace stencil::board::sherline_suzuki {
namespace {

enum class Kind : std::uint8_t { Real, Integer, Flag, Text, Reals3, Integers3, Flags3 };

struct Value {
  std::array<double, 3> n{};
  std::array<bool, 3> b{};
  std::string text;
};

// Which controller a key belongs to: the CY545's keys (its serial line, step rate, backlash, switches,
// homing and board) are left out with LinuxCNC, whose INI says those things for its mill, and
// [machine.linuxcnc] is left out with the CY545.
enum class Use : std::uint8_t { Any, Cy545, Linuxcnc };

// One key: its type, the range of every number in it, whether the file must have it (when its
// controller is the file's), its unit and meaning, where it goes, (when the range is not all) a check
// of its own: null, or what was expected; and the controller it belongs to.
struct Key {
  const char* name;
  Kind kind;
  double low, high;
  bool required;
  const char* meaning;
  void (*apply)(RigConfig&, const Value&);
  const char* (*check)(const Value&) = nullptr;
  Use use = Use::Any;
};

std::array<std::uint8_t, 3> bytes3(const Value& v) {
  return {static_cast<std::uint8_t>(v.n[0]), static_cast<std::uint8_t>(v.n[1]), static_cast<std::uint8_t>(v.n[2])};
}
constexpr double kNs = 1e6;  // nanoseconds per millisecond

const char* port_baud(const Value& v) {
  const double baud = v.n[0];
  return baud == 9600 || baud == 19200 || baud == 38400 || baud == 57600 ? nullptr : "9600, 19200, 38400 or 57600";
}
const char* one_resolution(const Value& v) {
  return v.n[0] == v.n[1] && v.n[1] == v.n[2]
             ? nullptr
             : "the same steps per mm on every axis (the frames and the planner take one resolution for all three)";
}
const char* unit_signs(const Value& v) {
  for (const double sign : v.n) {
    if (sign != 1.0 && sign != -1.0) return "1 or -1 per axis";
  }
  return nullptr;
}
const char* z_first(const Value& v) {
  const std::string& t = v.text;
  const bool permutation = t.size() == 3 && t.find('x') != std::string::npos && t.find('y') != std::string::npos &&
                           t.find('z') != std::string::npos;
  return permutation && t[0] == 'z' ? nullptr
                                    : "\"zxy\" or \"zyx\": each axis once, Z first (a tool left in the stock leaves it "
                                      "upwards, not through the work)";
}
const char* haptic_link_name(const Value& v) {
  return (v.text.rfind("pio:", 0) == 0 || v.text.rfind("can:", 0) == 0) && v.text.size() > 4 ? nullptr
                                                                                              : "pio:/dev/uioN or can:IFACE";
}
const char* device_path(const Value& v) {
  return v.text.size() > 1 && v.text[0] == '/' ? nullptr : "an absolute device path, e.g. /dev/ttyS0";
}
const char* distinct_channels(const Value& v) {
  return v.n[0] != v.n[1] && v.n[1] != v.n[2] && v.n[0] != v.n[2] ? nullptr : "a different channel per axis";
}
const char* controller_name(const Value& v) {
  return v.text == "cy545" || v.text == "linuxcnc" ? nullptr : "\"cy545\" or \"linuxcnc\"";
}
const char* ipv4_digits(const Value& v) {
  in_addr parsed{};
  return v.text.size() < 16 && ::inet_pton(AF_INET, v.text.c_str(), &parsed) == 1
             ? nullptr
             : "IPv4 digits, e.g. \"127.0.0.1\" (LinuxCNC on this box)";
}
// linuxcncrsh copies each password into a buffer of 16 bytes (char pwd[16], with strncpy of the whole
// argument: a longer one overruns it), and the rig sends it in a line of words ("hello PASSWORD ...").
const char* linuxcncrsh_password(const Value& v) {
  if (v.text == "EMC" || v.text == "EMCTOO") {
    return "a password of the rig's own: EMC and EMCTOO are linuxcncrsh's defaults, which anyone who reaches its "
           "port knows (it listens on every interface)";
  }
  bool word = !v.text.empty() && v.text.size() <= 15;
  for (const char c : v.text) word = word && c > ' ' && c < 0x7F;
  return word ? nullptr
              : "one word of 1 to 15 printable ASCII characters, no spaces (linuxcncrsh keeps 15: its buffer is 16 bytes)";
}
const char* some_path(const Value& v) { return v.text.empty() ? "the path of LinuxCNC's INI file" : nullptr; }

template <std::size_t N>
std::array<char, N> fixed_copy(const std::string& text) {
  std::array<char, N> out{};
  for (std::size_t i = 0; i + 1 < N && i < text.size(); ++i) out[i] = text[i];
  return out;
}

// clang-format off
const Key kKeys[] = {
  // [machine]: the mill (Sherline 3-axis) and its CY545 on the MMC-4S board, over RS-232.
  {"machine.serial_port", Kind::Text, 0, 0, true, "the CY545's RS-232 port",
   [](RigConfig& c, const Value& v) { c.serial_port = v.text; }, device_path, Use::Cy545},
  {"machine.serial_baud", Kind::Integer, 9600, 57600, true, "baud, 8N1; the CY545 finds the rate itself",
   [](RigConfig& c, const Value& v) { c.facts.serial_baud = static_cast<std::uint32_t>(v.n[0]); }, port_baud, Use::Cy545},
  {"machine.steps_per_mm", Kind::Reals3, 1, 100000, true, "motor steps per mm, x y z",
   [](RigConfig& c, const Value& v) { c.facts.steps_per_mm = v.n[0]; }, one_resolution},
  {"machine.axis_sign", Kind::Integers3, -1, 1, true,
   "x y z: +1 when machine steps count along the part's axis, -1 against it, as where the table moves under the tool",
   [](RigConfig& c, const Value& v) { c.facts.machine_sign = {static_cast<int>(v.n[0]), static_cast<int>(v.n[1]), static_cast<int>(v.n[2])}; },
   unit_signs},
  {"machine.travel_mm", Kind::Reals3, 1, 2000, true, "mm of workspace per axis from the home switch's edge",
   [](RigConfig& c, const Value& v) { c.facts.workspace_mm = v.n; }},
  {"machine.backlash_mm", Kind::Reals3, 0, 5, true, "mm of play per axis, a whole number of steps",
   [](RigConfig& c, const Value& v) { c.facts.backlash_mm = v.n; }, nullptr, Use::Cy545},
  {"machine.max_speed_mm_per_s", Kind::Real, 0.01, 100, true, "mm/s per axis",
   [](RigConfig& c, const Value& v) { c.facts.max_speed_mm_per_s = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.step_rate_steps_per_s", Kind::Integer, 1, 27000, true, "steps/s, the CY545's rate, 27000 at most",
   [](RigConfig& c, const Value& v) { c.facts.step_rate_steps_per_s = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.update_hz", Kind::Real, 1, 200, true,
   "machine updates per second: over the CY545's serial line, or at most 9 over linuxcncrsh",
   [](RigConfig& c, const Value& v) { c.facts.machine_update_hz = v.n[0]; }},
  {"machine.home_overtravel_mm", Kind::Real, 0, 50, true, "mm from the switch's edge down to the low hard stop",
   [](RigConfig& c, const Value& v) { c.facts.home_overtravel_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.far_overtravel_mm", Kind::Real, 0, 50, true, "mm past the workspace up to the high hard stop",
   [](RigConfig& c, const Value& v) { c.facts.far_overtravel_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.home_switch_edge_mm", Kind::Real, -50, 50, true, "machine mm at which the home switch opens",
   [](RigConfig& c, const Value& v) { c.facts.home_switch_edge_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.watchdog_relay_timeout_ms", Kind::Real, 50, 10000, true, "ms without a heartbeat before the relay drops",
   [](RigConfig& c, const Value& v) { c.facts.watchdog_relay_timeout_ns = static_cast<hal::MonotonicNs>(v.n[0] * kNs); }, nullptr, Use::Cy545},
  // The controller: the CY545 (above and below: cy545 only) or LinuxCNC ([machine.linuxcnc]).
  {"machine.controller", Kind::Text, 0, 0, false,
   "what drives the motors: \"cy545\", the default, or \"linuxcnc\" with [machine.linuxcnc]",
   [](RigConfig& c, const Value& v) {
     c.facts.controller = v.text == "linuxcnc" ? MachineController::Linuxcnc : MachineController::Cy545;
   }, controller_name},
  // [machine.linuxcnc]: LinuxCNC through linuxcncrsh (hal/linuxcnc), its axes' limits from its INI.
  {"machine.linuxcnc.address", Kind::Text, 0, 0, false, "LinuxCNC's box, IPv4 digits; absent: 127.0.0.1",
   [](RigConfig& c, const Value& v) { c.facts.linuxcnc.address = fixed_copy<16>(v.text); }, ipv4_digits, Use::Linuxcnc},
  {"machine.linuxcnc.port", Kind::Integer, 1, 65535, false, "linuxcncrsh's TCP port, its --port; absent: 5007",
   [](RigConfig& c, const Value& v) { c.facts.linuxcnc.port = static_cast<std::uint16_t>(v.n[0]); }, nullptr, Use::Linuxcnc},
  {"machine.linuxcnc.connect_password", Kind::Text, 0, 0, true, "linuxcncrsh's --connectpw, as the INI's DISPLAY gives it",
   [](RigConfig& c, const Value& v) { c.facts.linuxcnc.connect_password = fixed_copy<32>(v.text); }, linuxcncrsh_password,
   Use::Linuxcnc},
  {"machine.linuxcnc.enable_password", Kind::Text, 0, 0, true, "linuxcncrsh's --enablepw, as the INI's DISPLAY gives it",
   [](RigConfig& c, const Value& v) { c.facts.linuxcnc.enable_password = fixed_copy<32>(v.text); }, linuxcncrsh_password,
   Use::Linuxcnc},
  {"machine.linuxcnc.ini", Kind::Text, 0, 0, true,
   "LinuxCNC's INI file, read with this file; a relative path is from this file's folder",
   [](RigConfig& c, const Value& v) { c.linuxcnc_ini.source = v.text; }, some_path, Use::Linuxcnc},
  // [machine.homing]
  {"machine.homing.order", Kind::Text, 0, 0, true, "the axes in homing order",
   [](RigConfig& c, const Value& v) {
     for (std::size_t i = 0; i < 3; ++i) c.facts.homing_order[i] = static_cast<std::uint8_t>(v.text[i] - 'x');
   }, z_first, Use::Cy545},
  {"machine.homing.speed_mm_per_s", Kind::Real, 0.01, 100, true, "mm/s of the approach",
   [](RigConfig& c, const Value& v) { c.facts.homing_speed_mm_per_s = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.homing.slow_speed_mm_per_s", Kind::Real, 0.001, 100, true, "mm/s of the edge-finding steps",
   [](RigConfig& c, const Value& v) { c.facts.homing_slow_speed_mm_per_s = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.homing.chunk_mm", Kind::Real, 0.001, 10, true, "mm an approach may run into the switch",
   [](RigConfig& c, const Value& v) { c.facts.homing_chunk_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.homing.slack_mm", Kind::Real, 0, 10, true, "mm the departure may turn before the axis moves",
   [](RigConfig& c, const Value& v) { c.facts.homing_slack_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.homing.travel_mm", Kind::Real, 1, 5000, true, "mm of the longest approach (more than the whole travel)",
   [](RigConfig& c, const Value& v) { c.facts.homing_travel_mm = v.n[0]; }, nullptr, Use::Cy545},
  {"machine.homing.switch_zone_mm", Kind::Real, 0.1, 100, true, "mm: a switch still closed this far out is miswired",
   [](RigConfig& c, const Value& v) { c.facts.home_switch_zone_mm = v.n[0]; }, nullptr, Use::Cy545},
  // [machine.board]: the MMC-4S's wiring.
  {"machine.board.motor_channel", Kind::Integers3, 0, 3, true, "output-mux port of the x y z motors",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.motor_channel = bytes3(v); }, distinct_channels, Use::Cy545},
  {"machine.board.home_input", Kind::Integers3, 0, 7, true, "input-mux port of the x y z home switches",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.home_input = bytes3(v); }, distinct_channels, Use::Cy545},
  {"machine.board.spindle_output", Kind::Integer, 0, 7, true, "general-purpose output that runs the spindle",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.spindle_output = static_cast<std::uint8_t>(v.n[0]); }, nullptr, Use::Cy545},
  {"machine.board.heartbeat_output", Kind::Integer, -1, 7, true, "output the watchdog relay watches, -1: no relay",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.heartbeat_output = static_cast<int>(v.n[0]); }, nullptr, Use::Cy545},
  {"machine.board.heartbeat_period_ms", Kind::Real, 10, 5000, true, "ms per heartbeat (toggled every half)",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.heartbeat_period_ns = static_cast<hal::MonotonicNs>(v.n[0] * kNs); }, nullptr, Use::Cy545},
  {"machine.board.home_switch_closed_level", Kind::Flags3, 0, 0, true, "x y z: the level read while the switch is closed",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.home_switch_closed_level = v.b; }, nullptr, Use::Cy545},
  {"machine.board.channel_lines_latch_data", Kind::Flag, 0, 0, true, "true: each channel line latches its data bit",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.channel_lines_latch_data = v.b[0]; }, nullptr, Use::Cy545},
  {"machine.board.step_direction", Kind::Integers3, -1, 1, true,
   "x y z: +1 when the CY545's + steps move the axis away from its home switch, -1 when the direction line is wired the other way",
   [](RigConfig& c, const Value& v) { c.facts.mmc4s.step_direction = {static_cast<int>(v.n[0]), static_cast<int>(v.n[1]), static_cast<int>(v.n[2])}; },
   unit_signs, Use::Cy545},
  // [haptic]: the device (Suzuki 5-DOF) and the cycle.
  {"haptic.link", Kind::Text, 0, 0, true, "the device's link",
   [](RigConfig& c, const Value& v) { c.haptic_link = v.text; }, haptic_link_name},
  {"haptic.reach_mm", Kind::Reals3, 10, 5000, true, "device mm of reach, x y z",
   [](RigConfig& c, const Value& v) { c.facts.haptic_workspace_mm = v.n; }},
  {"haptic.reach_margin_mm", Kind::Real, 0, 500, true, "device mm outside the reach still taken as a sample",
   [](RigConfig& c, const Value& v) { c.facts.device_reach_margin_mm = v.n[0]; }},
  {"haptic.device_mm_per_machine_mm", Kind::Real, 0.1, 100, true, "the haptic-to-machine scale",
   [](RigConfig& c, const Value& v) { c.facts.haptic_to_machine_scale = v.n[0]; }},
  {"haptic.force_limit_n", Kind::Real, 0.5, 5, true, "N, at most the board's 5 N: no file raises it",
   [](RigConfig& c, const Value& v) { c.facts.force_limit_n = v.n[0]; }},
  {"haptic.torque_limit_nmm", Kind::Real, 1, 200, true, "N mm, the two displayed torques",
   [](RigConfig& c, const Value& v) { c.facts.torque_limit_nmm = v.n[0]; }},
  {"haptic.angle_limit_rad", Kind::Real, 0.1, 3.2, true, "rad, the two sensed angles",
   [](RigConfig& c, const Value& v) { c.facts.angle_limit_rad = v.n[0]; }},
  {"haptic.rate_hz", Kind::Real, 250, 4000, true, "the cycle's rate",
   [](RigConfig& c, const Value& v) { c.facts.haptic_rate_hz = v.n[0]; }},
  // [controller]
  {"controller.virtual_tool_speed_mm_per_s", Kind::Real, 0.01, 100, true, "mm/s, at most the mill's",
   [](RigConfig& c, const Value& v) { c.facts.virtual_tool_speed_mm_per_s = v.n[0]; }},
  {"controller.standoff_mm", Kind::Real, 0, 1, true, "mm the virtual tool keeps clear of the part",
   [](RigConfig& c, const Value& v) { c.facts.machine_standoff_mm = v.n[0]; }},
  {"controller.stock_model_cell_mm", Kind::Real, 0.01, 1, true, "mm cells of the model of the machined stock",
   [](RigConfig& c, const Value& v) { c.facts.stock_model_cell_mm = v.n[0]; }},
  {"controller.overrun_limit", Kind::Integer, 1, 100, true, "overruns in a row before a safe state",
   [](RigConfig& c, const Value& v) { c.facts.overrun_limit = static_cast<int>(v.n[0]); }},
  {"controller.stale_periods", Kind::Integer, 1, 100, true, "periods without a fresh sample before a safe state",
   [](RigConfig& c, const Value& v) { c.facts.stale_periods = static_cast<int>(v.n[0]); }},
  {"controller.start_held", Kind::Flag, 0, 0, true, "start held until the hand is still near the tool",
   [](RigConfig& c, const Value& v) { c.facts.start_held = v.b[0]; }},
  // [threads]
  {"threads.cycle_cpu", Kind::Integer, -1, 1023, false, "CPU the cycle is pinned to, -1: none",
   [](RigConfig& c, const Value& v) { c.cycle_cpu = static_cast<int>(v.n[0]); }},
  {"threads.cycle_priority", Kind::Integer, 2, 99, true, "the cycle's SCHED_FIFO priority",
   [](RigConfig& c, const Value& v) { c.cycle_priority = static_cast<int>(v.n[0]); }},
  {"threads.machine_priority", Kind::Integer, 1, 98, true, "the machine thread's SCHED_FIFO priority, below the cycle's",
   [](RigConfig& c, const Value& v) { c.machine_priority = static_cast<int>(v.n[0]); }},
  // [job]
  {"job.work_offset_mm", Kind::Reals3, -10000, 10000, true, "x y z: the tool tip in the part's frame at home",
   [](RigConfig& c, const Value& v) { c.work_offset_mm = v.n; }},
  {"job.output_folder", Kind::Text, 0, 0, false,
   "the jobs folder, each job's own folder in it; empty or absent: $XDG_STATE_HOME/stencil/jobs (--out-dir overrides)",
   [](RigConfig& c, const Value& v) { c.output_folder = v.text; }},
  {"job.keep_jobs", Kind::Integer, 0, 100000, false,
   "job folders kept as a new job starts, it counted; never one that may be resumed (0: all; absent: 50)",
   [](RigConfig& c, const Value& v) { c.keep_jobs = static_cast<unsigned>(v.n[0]); }},
  {"job.keep_mb", Kind::Integer, 0, 100000000, false,
   "MB of job folders kept as a new job starts, newest first; never one that may be resumed (0 or absent: no cap)",
   [](RigConfig& c, const Value& v) { c.keep_mb = static_cast<unsigned>(v.n[0]); }},
  // [commissioning]
  {"commissioning.jog_mm", Kind::Real, 0.5, 20, true, "mm each axis moves into its travel, then back half of it",
   [](RigConfig& c, const Value& v) { c.commissioning.jog_mm = v.n[0]; }},
  {"commissioning.tolerance_mm", Kind::Real, 0.001, 1, true, "mm a reading may differ from the commanded move",
   [](RigConfig& c, const Value& v) { c.commissioning.tolerance_mm = v.n[0]; }},
};
// clang-format on

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::Real: return "a number";
    case Kind::Integer: return "an integer";
    case Kind::Flag: return "true or false";
    case Kind::Text: return "a quoted string";
    case Kind::Reals3: return "an array of 3 numbers";
    case Kind::Integers3: return "an array of 3 integers";
    case Kind::Flags3: return "an array of 3 true/false";
  }
  return "?";
}

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string expected_of(const Key& key) {
  std::string text = kind_name(key.kind);
  if (key.kind != Kind::Text && key.kind != Kind::Flag && key.kind != Kind::Flags3) {
    text += " from " + number_text(key.low) + " to " + number_text(key.high);
  }
  return text + " (" + key.meaning + ")";
}

// One scalar of `key`'s type into `number`/`flag`/`text`: false when the node is of another type.
bool read_scalar(const toml::node& node, Kind kind, double& number, bool& flag, std::string& text) {
  switch (kind) {
    case Kind::Real:
    case Kind::Reals3:
      if (!node.is_number() || !node.value<double>().has_value()) return false;  // (an integer past 2^53 has none)
      number = *node.value<double>();
      return true;
    case Kind::Integer:
    case Kind::Integers3:
      if (!node.is_integer()) return false;
      number = static_cast<double>(node.value<std::int64_t>().value_or(0));
      return true;
    case Kind::Flag:
    case Kind::Flags3:
      if (!node.is_boolean()) return false;
      flag = node.value<bool>().value_or(false);
      return true;
    case Kind::Text:
      if (!node.is_string()) return false;
      text = node.value<std::string>().value_or("");
      return true;
  }
  return false;
}

// The node as `key`'s value, its type and range checked: "" or what is wrong.
std::string read_value(const toml::node& node, const Key& key, Value& value) {
  const bool triple = key.kind == Kind::Reals3 || key.kind == Kind::Integers3 || key.kind == Kind::Flags3;
  const toml::array* array = node.as_array();
  if (triple != (array != nullptr) || (triple && array->size() != 3)) {
    return "expected " + expected_of(key);
  }
  for (std::size_t i = 0; i < (triple ? 3U : 1U); ++i) {
    const toml::node& element = triple ? *array->get(i) : node;
    if (!read_scalar(element, key.kind, value.n[i], value.b[i], value.text)) {
      return "expected " + expected_of(key);
    }
    const bool numeric = key.kind != Kind::Text && key.kind != Kind::Flag && key.kind != Kind::Flags3;
    if (numeric && !(value.n[i] >= key.low && value.n[i] <= key.high)) {
      return number_text(value.n[i]) + " is out of range: expected " + expected_of(key);
    }
  }
  const char* wrong = key.check == nullptr ? nullptr : key.check(value);
  return wrong == nullptr ? "" : "expected " + std::string(wrong);
}

const Key* find_key(const std::string& name) {
  for (const Key& key : kKeys) {
    if (name == key.name) return &key;
  }
  return nullptr;
}

bool is_section(const std::string& name) {
  const std::string prefix = name + ".";
  for (const Key& key : kKeys) {
    if (std::string(key.name).rfind(prefix, 0) == 0) return true;
  }
  return false;
}

struct Reading {
  const std::string& source;
  RigConfig& config;
  std::map<std::string, long> lines;  // every key read, and its line
  std::string error;
};

std::string at(const std::string& source, long line) { return source + ":" + std::to_string(line) + ": "; }

// Where a missing key belongs: its section's header line, or the file's end when there is no such section.
std::string where_missing(const toml::table& root, const std::string& name, const std::string& source) {
  const std::string section = name.substr(0, name.rfind('.'));
  const toml::node* node = root.at_path(section).node();
  if (node != nullptr && node->is_table() && node->source().begin.line > 0) {
    return at(source, static_cast<long>(node->source().begin.line)) + "[" + section + "]: ";
  }
  return source + ": no [" + section + "] section: ";
}

bool read_table(const toml::table& table, const std::string& prefix, Reading& reading) {
  for (auto&& [name_key, node] : table) {
    const std::string name = prefix + std::string(name_key.str());
    const long line = static_cast<long>(node.source().begin.line);
    if (is_section(name)) {
      if (!node.is_table()) {
        reading.error = at(reading.source, line) + name + ": expected the table [" + name + "], not a value";
        return false;
      }
      if (!read_table(*node.as_table(), name + ".", reading)) return false;
      continue;
    }
    const Key* key = find_key(name);
    if (key == nullptr) {
      reading.error = at(reading.source, line) + "unknown key '" + name +
                      "' (every key is in board/sherline_suzuki/rig.toml and stencil-rig --config-keys)";
      return false;
    }
    Value value;
    const std::string wrong = read_value(node, *key, value);
    if (!wrong.empty()) {
      reading.error = at(reading.source, line) + name + ": " + wrong;
      return false;
    }
    key->apply(reading.config, value);
    reading.lines[name] = line;
  }
  return true;
}

// "file:line: " of a key that was read (the file alone when it was not).
struct Where {
  const std::map<std::string, long>& lines;
  const std::string& source;
  std::string operator()(const char* name) const {
    const auto found = lines.find(name);
    return found == lines.end() ? source + ": " : at(source, found->second);
  }
};

std::string standoff_contradiction(const RigFacts& f, const Where& where) {
  if (f.machine_standoff_mm < standoff_needed_mm(f)) {
    return where("controller.standoff_mm") + "controller.standoff_mm " + number_text(f.machine_standoff_mm) +
           " is under the " + number_text(standoff_needed_mm(f)) + " mm the planner's fallback staircase needs at " +
           number_text(f.steps_per_mm) + " steps/mm";
  }
  return "";
}

// Facts that contradict each other, or a ceiling of the hardware (a CY545 rig): "" or the message.
std::string contradiction(const RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  const RigFacts& f = c.facts;
  const Where where{lines, source};
  const double needed_rate = f.max_speed_mm_per_s * f.steps_per_mm;
  if (needed_rate > f.step_rate_steps_per_s + 1e-9) {
    return where("machine.max_speed_mm_per_s") + "machine.max_speed_mm_per_s " + number_text(f.max_speed_mm_per_s) +
           " needs " + number_text(needed_rate) + " steps/s at " + number_text(f.steps_per_mm) +
           " steps/mm, above machine.step_rate_steps_per_s " + number_text(f.step_rate_steps_per_s);
  }
  if (f.virtual_tool_speed_mm_per_s > f.max_speed_mm_per_s) {
    return where("controller.virtual_tool_speed_mm_per_s") + "controller.virtual_tool_speed_mm_per_s " +
           number_text(f.virtual_tool_speed_mm_per_s) + " is above machine.max_speed_mm_per_s " +
           number_text(f.max_speed_mm_per_s) + ": the mill could not follow the tool";
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const double steps = f.backlash_mm[axis] * f.steps_per_mm;
    if (std::fabs(steps - std::round(steps)) > 1e-6) {
      return where("machine.backlash_mm") + "machine.backlash_mm " + number_text(f.backlash_mm[axis]) + " on " +
             static_cast<char>('x' + axis) + " is " + number_text(steps) + " steps: expected a whole number of steps";
    }
  }
  const std::string standoff = standoff_contradiction(f, where);
  if (!standoff.empty()) {
    return standoff;
  }
  if (!motion::follow_fallback_fits(planner_limits(f))) {
    return where("machine.update_hz") + "one machine update (machine.update_hz " + number_text(f.machine_update_hz) +
           ") is too short for the planner's fallback staircase at machine.step_rate_steps_per_s " +
           number_text(f.step_rate_steps_per_s);
  }
  return "";
}

std::string homing_contradiction(const RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  const RigFacts& f = c.facts;
  const Where where{lines, source};
  if (f.homing_speed_mm_per_s >= f.max_speed_mm_per_s || f.homing_slow_speed_mm_per_s > f.homing_speed_mm_per_s) {
    return where("machine.homing.speed_mm_per_s") + "machine.homing.speed_mm_per_s " +
           number_text(f.homing_speed_mm_per_s) + ": expected below machine.max_speed_mm_per_s " +
           number_text(f.max_speed_mm_per_s) + " and at least machine.homing.slow_speed_mm_per_s " +
           number_text(f.homing_slow_speed_mm_per_s);
  }
  if (f.homing_slack_mm <= largest_backlash_mm(f)) {
    return where("machine.homing.slack_mm") + "machine.homing.slack_mm " + number_text(f.homing_slack_mm) +
           ": expected above the largest backlash, " + number_text(largest_backlash_mm(f)) + " mm";
  }
  if (f.home_switch_zone_mm <= f.home_overtravel_mm) {
    return where("machine.homing.switch_zone_mm") + "machine.homing.switch_zone_mm " +
           number_text(f.home_switch_zone_mm) + ": expected above machine.home_overtravel_mm " +
           number_text(f.home_overtravel_mm);
  }
  for (int axis = 0; axis < 3; ++axis) {
    const double whole = travel_max_mm(axis, f) - travel_min_mm(axis, f);
    if (f.homing_travel_mm <= whole) {
      return where("machine.homing.travel_mm") + "machine.homing.travel_mm " + number_text(f.homing_travel_mm) +
             ": expected more than " + static_cast<char>('x' + axis) + "'s whole travel, " + number_text(whole) + " mm";
    }
  }
  return "";
}

// What any rig's threads and commissioning must keep to: "" or the message.
std::string threads_contradiction(const RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  const RigFacts& f = c.facts;
  const Where where{lines, source};
  if (c.machine_priority >= c.cycle_priority) {
    return where("threads.machine_priority") + "threads.machine_priority " + std::to_string(c.machine_priority) +
           ": expected below threads.cycle_priority " + std::to_string(c.cycle_priority);
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (c.commissioning.jog_mm >= f.workspace_mm[axis]) {
      return where("commissioning.jog_mm") + "commissioning.jog_mm " + number_text(c.commissioning.jog_mm) +
             ": expected under every axis's travel (" + static_cast<char>('x' + axis) + ": " +
             number_text(f.workspace_mm[axis]) + " mm)";
    }
  }
  return "";
}

// The most updates a second over linuxcncrsh: it answers a set once LinuxCNC's task has taken it,
// polling for that every 0.1 s, and each update sends one (a G1), so about 8 a second are kept.
constexpr double kLinuxcncMaxUpdateHz = 9.0;

// A LinuxCNC rig's facts against each other and against its INI: "" or the message.
std::string linuxcnc_contradiction(const RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  const RigFacts& f = c.facts;
  const Where where{lines, source};
  if (f.machine_update_hz > kLinuxcncMaxUpdateHz) {
    return where("machine.update_hz") + "machine.update_hz " + number_text(f.machine_update_hz) +
           ": expected at most 9 with machine.controller = \"linuxcnc\": each update is one G1 over linuxcncrsh, which "
           "answers a set after about 100 ms (it polls every 0.1 s), so 8 updates a second is what it keeps";
  }
  const std::string travel = linuxcnc_travel_outside_limits(c.linuxcnc_ini, f.workspace_mm);
  if (!travel.empty()) {
    return where("machine.travel_mm") + "machine.travel_mm: " + travel;
  }
  const std::string display = linuxcnc_display_disagreement(c.linuxcnc_ini, f.linuxcnc.port, f.linuxcnc.connect_password.data(),
                                                            f.linuxcnc.enable_password.data());
  if (!display.empty()) {
    return where("machine.linuxcnc.ini") + "machine.linuxcnc.ini: " + display;
  }
  const motion::PlannerLimits limits = planner_limits(f);
  const double slowest_mm = linuxcnc_shortest_update_move_mm(f);
  const std::string axes = " mm from rest to rest in one update (1/" + number_text(f.machine_update_hz) +
                           " s) on its slowest axis, as the INI's MAX_VELOCITY and MAX_ACCELERATION allow";
  if (f.virtual_tool_speed_mm_per_s > limits.speed.max_axis_speed_mm_per_s) {
    return where("controller.virtual_tool_speed_mm_per_s") + "controller.virtual_tool_speed_mm_per_s " +
           number_text(f.virtual_tool_speed_mm_per_s) + " is above the " +
           number_text(limits.speed.max_axis_speed_mm_per_s) + " mm/s the LinuxCNC mill makes good (" +
           number_text(slowest_mm) + axes + "): the mill could not follow the tool";
  }
  const std::string standoff = standoff_contradiction(f, where);
  if (!standoff.empty()) {
    return standoff;
  }
  if (!motion::follow_fallback_fits(limits)) {
    return where("machine.update_hz") + "one machine update (machine.update_hz " + number_text(f.machine_update_hz) +
           ") is too short for the planner's fallback move at " + number_text(f.steps_per_mm) +
           " steps/mm: the LinuxCNC mill goes " + number_text(slowest_mm) + axes;
  }
  // What the link checks again as it starts (hal::linuxcnc::check_linuxcnc_config) is covered by the
  // keys' own checks above: its tests hold the two together (rig_config_tests).
  return "";
}

std::string wiring_contradiction(const RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  const RigFacts& f = c.facts;
  const Where where{lines, source};
  if (f.mmc4s.heartbeat_output == f.mmc4s.spindle_output) {
    return where("machine.board.heartbeat_output") + "machine.board.heartbeat_output: expected another output than "
           "the spindle's";
  }
  // The heartbeat toggles every half period, at a machine update: the relay must not drop between two.
  const double gap_ms = static_cast<double>(f.mmc4s.heartbeat_period_ns) / 2e6 + 1000.0 / f.machine_update_hz;
  const double relay_ms = static_cast<double>(f.watchdog_relay_timeout_ns) / 1e6;
  if (f.mmc4s.heartbeat_output >= 0 && 2.0 * gap_ms > relay_ms) {
    return where("machine.watchdog_relay_timeout_ms") + "machine.watchdog_relay_timeout_ms " + number_text(relay_ms) +
           ": expected at least twice the heartbeat's longest gap (half of machine.board.heartbeat_period_ms plus one "
           "machine update: " + number_text(gap_ms) + " ms), or the relay cuts the power of a running mill";
  }
  // Every homing rate and leg is at least one step at the configured steps per mm.
  if (mm_to_steps(f.homing_slow_speed_mm_per_s, f) < 1 || mm_to_steps(f.homing_chunk_mm, f) < 1) {
    return where("machine.homing.slow_speed_mm_per_s") + "machine.homing.slow_speed_mm_per_s " +
           number_text(f.homing_slow_speed_mm_per_s) + " and machine.homing.chunk_mm " + number_text(f.homing_chunk_mm) +
           ": expected each at least one step at " + number_text(f.steps_per_mm) + " steps/mm";
  }
  return "";
}

bool belongs(const Key& key, MachineController controller) {
  return key.use == Use::Any || (key.use == Use::Cy545) == (controller == MachineController::Cy545);
}

const char* controller_text(MachineController controller) {
  return controller == MachineController::Linuxcnc ? "\"linuxcnc\"" : "\"cy545\"";
}

// A section or key of the other controller's (an empty section counts): "" or the message.
std::string misplaced(const toml::table& root, const RigConfig& c, const std::map<std::string, long>& lines,
                      const std::string& source) {
  const MachineController controller = c.facts.controller;
  const bool linuxcnc = controller == MachineController::Linuxcnc;
  const std::string chosen = std::string("machine.controller is ") + controller_text(controller) +
                             (lines.count("machine.controller") == 0 ? " (absent: the CY545)" : "");
  using Sections = std::array<const char*, 2>;
  for (const char* section : linuxcnc ? Sections{"machine.homing", "machine.board"} : Sections{"machine.linuxcnc", nullptr}) {
    const toml::node* node = section == nullptr ? nullptr : root.at_path(section).node();
    if (node != nullptr) {
      const std::string where =
          node->source().begin.line > 0 ? at(source, static_cast<long>(node->source().begin.line)) : source + ": ";
      return where + "[" + section + "]: " + chosen + ": expected no [" + section + "] section" +
             (linuxcnc ? " (the CY545's: LinuxCNC's INI and HAL files say this for its mill)"
                       : " (set machine.controller = \"linuxcnc\" to drive the mill through LinuxCNC)");
    }
  }
  for (const Key& key : kKeys) {
    const auto found = lines.find(key.name);
    if (found != lines.end() && !belongs(key, controller)) {
      return at(source, found->second) + key.name + ": " + chosen + ": expected no " + key.name +
             (linuxcnc ? " (the CY545's: LinuxCNC's INI holds what its mill needs)" : " (LinuxCNC's only)");
    }
  }
  return "";
}

// machine.linuxcnc.ini as a path: as given when absolute, else from the folder of `source` (the
// configuration file's path; with no folder in it, the current one).
std::string ini_path(const std::string& ini, const std::string& source) {
  const std::size_t slash = source.rfind('/');
  if (ini.empty() || ini[0] == '/' || slash == std::string::npos) {
    return ini;
  }
  return source.substr(0, slash + 1) + ini;
}

// LinuxCNC's INI read into the configuration's facts: "" or the message (the INI's own, after the key).
std::string take_linuxcnc_ini(RigConfig& c, const std::map<std::string, long>& lines, const std::string& source) {
  LinuxcncIni ini;
  std::string error;
  if (!read_linuxcnc_ini(ini_path(c.linuxcnc_ini.source, source), ini, error)) {
    return Where{lines, source}("machine.linuxcnc.ini") + "machine.linuxcnc.ini: " + error;
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    c.facts.linuxcnc.max_velocity_mm_per_s[axis] = ini.axes[axis].max_velocity_mm_per_s.value;
    c.facts.linuxcnc.max_acceleration_mm_per_s2[axis] = ini.axes[axis].max_acceleration_mm_per_s2.value;
  }
  c.facts.linuxcnc.max_linear_velocity_mm_per_s = ini.max_linear_velocity_mm_per_s.value;
  c.linuxcnc_ini = std::move(ini);
  return "";
}

}  // namespace

bool parse_rig_config(std::string_view text, const std::string& source, RigConfig& config, std::string& error) {
  // ASCII only, comments included: toml++ 3.3.0 (Debian 12's) reaches __builtin_unreachable() on some
  // non-ASCII code points (U+02B6 among them, in is_non_ascii_horizontal_whitespace), found by
  // fuzz_rig_config; nothing in a rig's file needs more than ASCII.
  long line = 1;
  for (std::size_t offset = 0; offset < text.size(); ++offset) {
    const auto byte = static_cast<unsigned char>(text[offset]);
    if (byte >= 0x80) {
      char found[96];
      std::snprintf(found, sizeof found, "byte 0x%02X at offset %zu: expected ASCII text", byte, offset);
      error = at(source, line) + found;
      return false;
    }
    line += byte == '\n' ? 1 : 0;
  }
  toml::parse_result parsed = toml::parse(text, source);
  if (!parsed) {
    error = at(source, static_cast<long>(parsed.error().source().begin.line)) + std::string(parsed.error().description());
    return false;
  }
  RigConfig read = config;
  // The controller and LinuxCNC's facts are the file's alone: absent keys take the defaults, not
  // whatever `config` held (the CY545 and no LinuxCNC; "127.0.0.1" and 5007).
  read.facts.controller = kRig.controller;
  read.facts.linuxcnc = kRig.linuxcnc;
  read.linuxcnc_ini = LinuxcncIni{};
  Reading reading{source, read, {}, {}};
  if (!read_table(parsed.table(), "", reading)) {
    error = reading.error;
    return false;
  }
  const MachineController controller = read.facts.controller;
  error = misplaced(parsed.table(), read, reading.lines, source);
  if (!error.empty()) {
    return false;
  }
  for (const Key& key : kKeys) {
    if (key.required && belongs(key, controller) && reading.lines.count(key.name) == 0) {
      error = where_missing(parsed.table(), key.name, source) + "missing the key '" + key.name + "': expected " +
              expected_of(key) + (key.use == Use::Linuxcnc ? " (machine.controller is \"linuxcnc\")" : "");
      return false;
    }
  }
  if (controller == MachineController::Linuxcnc) {
    error = take_linuxcnc_ini(read, reading.lines, source);
    if (error.empty()) {
      error = linuxcnc_contradiction(read, reading.lines, source);
    }
    if (error.empty()) {
      error = threads_contradiction(read, reading.lines, source);
    }
  } else {
    error = contradiction(read, reading.lines, source);
    if (error.empty()) {
      error = homing_contradiction(read, reading.lines, source);
    }
    if (error.empty()) {
      error = threads_contradiction(read, reading.lines, source);
    }
    if (error.empty()) {
      error = wiring_contradiction(read, reading.lines, source);
    }
  }
  if (!error.empty()) {
    return false;
  }
  config = read;
  return true;
}

namespace {

// Who may change the file (its owner: this program's user or root; nobody through its group or
// everyone) and who may replace it (its folder: not writable by others unless sticky, as /tmp is).
bool trusted(const std::string& path, const struct stat& file, std::string& error) {
  if (!S_ISREG(file.st_mode)) {
    error = path + ": not a regular file";
    return false;
  }
  if (file.st_uid != 0 && file.st_uid != ::geteuid()) {
    error = path + ": owned by user " + std::to_string(file.st_uid) + ": expected this program's user (" +
            std::to_string(::geteuid()) + ") or root, since the file decides where the tool goes";
    return false;
  }
  if ((file.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(file.st_mode & 07777));
    error = path + ": writable by other users (mode " + mode + "): expected writable by its owner only (chmod go-w " +
            path + ")";
    return false;
  }
  const std::size_t slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  struct stat parent {};
  if (::stat(folder.c_str(), &parent) == 0 && (parent.st_mode & (S_IWGRP | S_IWOTH)) != 0 &&
      (parent.st_mode & S_ISVTX) == 0) {
    error = path + ": its folder " + folder + " is writable by other users, who could replace the file: expected "
            "chmod go-w " + folder;
    return false;
  }
  return true;
}

}  // namespace

bool read_rig_config(const std::string& path, RigConfig& config, std::string& error) {
  // Opened once, not followed through a link, and checked through the descriptor it is read from.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    error = path + (errno == ELOOP ? ": a symbolic link: expected the file itself" : ": no such configuration file");
    return false;
  }
  struct stat status {};
  std::string text;
  bool ok = ::fstat(fd, &status) == 0 && trusted(path, status, error);
  while (ok && text.size() < (1U << 20)) {
    char chunk[4096];
    const ssize_t got = ::read(fd, chunk, sizeof chunk);
    if (got < 0) {
      error = path + ": could not be read";
      ok = false;
    } else if (got == 0) {
      break;
    } else {
      text.append(chunk, static_cast<std::size_t>(got));
    }
  }
  ::close(fd);
  if (ok && text.size() >= (1U << 20)) {
    error = path + ": over 1 MiB: expected a rig's configuration";
    ok = false;
  }
  RigConfig read = config;
  if (!ok || !parse_rig_config(text, path, read, error)) {
    return false;
  }
  // The journals' folder is looked at now, not when the first journal opens after the devices.
  struct stat folder {};
  if (!read.output_folder.empty() && (::stat(read.output_folder.c_str(), &folder) != 0 || !S_ISDIR(folder.st_mode) ||
                                      ::access(read.output_folder.c_str(), W_OK | X_OK) != 0)) {
    error = path + ": job.output_folder " + read.output_folder + ": expected a folder this program may write in";
    return false;
  }
  config = read;
  config.file_crc32 = static_cast<std::uint32_t>(
      ::crc32(::crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(text.data()), static_cast<uInt>(text.size())));
  if (config.facts.controller == MachineController::Linuxcnc) {
    // The file followed by its INI: a job resumes only under the same two.
    config.file_crc32 = static_cast<std::uint32_t>(::crc32_combine(config.file_crc32, config.linuxcnc_ini.crc32,
                                                                   static_cast<z_off_t>(config.linuxcnc_ini.size)));
  }
  return true;
}

std::string describe_rig_config_keys() {
  std::string text;
  for (const Key& key : kKeys) {
    const char* use = key.use == Use::Cy545 ? "cy545 only" : key.use == Use::Linuxcnc ? "linuxcnc only" : "";
    const std::string optional = key.required ? "" : "optional";
    const std::string marks = optional + (optional.empty() || *use == '\0' ? "" : ", ") + use;
    text += std::string(key.name) + (marks.empty() ? "" : " (" + marks + ")") + ": " + expected_of(key) + "\n";
  }
  return text;
}

}  // namespace stencil::board::sherline_suzuki
