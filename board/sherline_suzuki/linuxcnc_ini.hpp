// LinuxCNC's INI file, read for what a rig driven through LinuxCNC takes from it: the units, each
// axis's top speed, acceleration and soft limits, the path's top speed, and how LinuxCNC starts its
// display (linuxcncrsh, its port and passwords). Read once, when the rig's configuration is loaded
// (init time: it allocates). Every refusal names the INI file, the line and the key.
//
// The syntax is LinuxCNC's: [SECTION] headers, KEY = VALUE lines, comment lines starting with # or ;
// (after blanks), blank lines; names are case-sensitive. A value is the rest of its line, so a
// comment after a number is not one (refused as not a number). #INCLUDE, which the linuxcnc script
// expands into a copy of its own, is refused: point the rig at the expanded file.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace stencil::board::sherline_suzuki {

// A number the INI gives, and its line (0: not given).
struct IniNumber {
  double value = 0.0;
  long line = 0;
};

struct LinuxcncIniAxis {
  IniNumber max_velocity_mm_per_s;       // [AXIS_X] MAX_VELOCITY, above 0
  IniNumber max_acceleration_mm_per_s2;  // MAX_ACCELERATION, above 0
  IniNumber min_limit_mm;                // MIN_LIMIT: the soft limit, machine mm
  IniNumber max_limit_mm;                // MAX_LIMIT, above MIN_LIMIT
};

// [DISPLAY] DISPLAY as linuxcncrsh's command line (its options as linuxcncrsh takes them: --port N,
// --port=N or -p N; --connectpw / -w; --enablepw / -e).
struct LinuxcncrshOptions {
  long line = 0;
  std::uint16_t port = 5007;        // --port, else linuxcncrsh's default
  std::string connect_password;     // --connectpw (always given: without it linuxcncrsh takes EMC)
  std::string enable_password;      // --enablepw (always given: without it EMCTOO)
};

struct LinuxcncIni {
  std::string source;                        // the file as messages name it
  std::array<LinuxcncIniAxis, 3> axes{};     // x y z
  IniNumber max_linear_velocity_mm_per_s;    // [TRAJ] MAX_LINEAR_VELOCITY (optional)
  LinuxcncrshOptions display;
  std::uint32_t crc32 = 0;                   // of the file's bytes
  std::size_t size = 0;                      // bytes
};

// Reads `text` (named `source` in messages) into `ini`. False with `error` ("source:line: [SECTION]
// KEY: what was expected") on a line that is not INI, a repeated key this reads, a missing one,
// [TRAJ] LINEAR_UNITS other than mm or metric, a number that is not one, not finite or out of its
// range, MIN_LIMIT not below MAX_LIMIT, or a DISPLAY that is not linuxcncrsh, leaves its passwords
// at linuxcncrsh's defaults, or still holds a template's @PLACEHOLDER@.
[[nodiscard]] bool parse_linuxcnc_ini(std::string_view text, const std::string& source, LinuxcncIni& ini,
                                      std::string& error);

// The file at `path` (a regular file of at most 1 MiB; opened without waiting on a FIFO), parsed.
[[nodiscard]] bool read_linuxcnc_ini(const std::string& path, LinuxcncIni& ini, std::string& error);

// The workspace [0, travel_mm] (machine mm, 0 at home) outside an axis's [MIN_LIMIT, MAX_LIMIT]:
// the message naming the INI's line and key, else "".
[[nodiscard]] std::string linuxcnc_travel_outside_limits(const LinuxcncIni& ini, const std::array<double, 3>& travel_mm);

// The rig's port and passwords against what DISPLAY starts linuxcncrsh with: the message naming the
// INI's line and the option that differs (never the passwords themselves), else "".
[[nodiscard]] std::string linuxcnc_display_disagreement(const LinuxcncIni& ini, std::uint16_t port,
                                                        std::string_view connect_password,
                                                        std::string_view enable_password);

}  // namespace stencil::board::sherline_suzuki
