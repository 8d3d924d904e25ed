// The rig in a configuration file (TOML, for example /etc/stencil/rig.toml): every fact of the rig
// (rig_facts.hpp) and what the program needs to run it (its serial port, haptic link, threads, work
// offset, output folder), read and checked before any device is opened. The shipped example,
// board/sherline_suzuki/rig.toml, holds every key with its unit and range and equals the compiled-in
// defaults (kRig). A mill driven by LinuxCNC (machine.controller = "linuxcnc", the example
// rig-linuxcnc.toml) names LinuxCNC's INI file instead of the CY545's keys; the INI is read with the
// file (linuxcnc_ini.hpp) and its axes' limits become facts.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "board/sherline_suzuki/commissioning.hpp"
#include "board/sherline_suzuki/linuxcnc_ini.hpp"
#include "board/sherline_suzuki/rig_facts.hpp"

namespace stencil::board::sherline_suzuki {

struct RigConfig {
  RigFacts facts = kRig;
  std::string serial_port;          // the CY545's RS-232 port, e.g. /dev/ttyS0
  std::string haptic_link;          // pio:/dev/uioN or can:IFACE
  int cycle_cpu = -1;               // -1: not pinned
  int cycle_priority = 80;          // SCHED_FIFO
  int machine_priority = 70;        // SCHED_FIFO, below the cycle (it always preempts the machine thread)
  std::array<double, 3> work_offset_mm = kHomeWorldMm;  // the tool tip in the part's frame with the machine at home
  std::string output_folder;        // the jobs folder, each job's own folder in it ("": the program's default)
  unsigned keep_jobs = 50;          // job folders kept as a new job starts, it counted (0: every one)
  unsigned keep_mb = 0;             // MB of job folders kept as a new job starts (0: no cap)
  CommissioningSettings commissioning;
  // LinuxCNC's INI as it was read (controller linuxcnc; empty source otherwise): its path (a relative
  // machine.linuxcnc.ini resolved from the configuration file's folder), its numbers and their lines.
  LinuxcncIni linuxcnc_ini;
  // The file's CRC-32, recorded with a job (0: the compiled-in rig); with LinuxCNC, the CRC-32 of the
  // file followed by its INI, since both decide where the tool goes.
  std::uint32_t file_crc32 = 0;
};

// Reads `text` (named `source` in messages) over the defaults in `config`. False with `error` naming
// the source, the line, the key and what was expected: an unknown key, a missing required key, a
// wrong type, a value out of its range or against the rig's hard ceilings (the force at most the
// board's 5 N, the speed at most what the mill's steps allow), or facts that contradict each other.
// With machine.controller = "linuxcnc" it also reads LinuxCNC's INI (machine.linuxcnc.ini; relative
// to the folder of `source`, a path) and refuses what contradicts it, naming the INI's line and key;
// the CY545's keys are left out then (refused if given), as [machine.linuxcnc] is with the CY545.
[[nodiscard]] bool parse_rig_config(std::string_view text, const std::string& source, RigConfig& config,
                                    std::string& error);

// The file at `path`: refused first when it is a symbolic link, when a user other than this process's
// own or root owns it or can write to it (group- or world-writable), or when its folder lets others
// replace it, since what it says decides where a real tool goes.
[[nodiscard]] bool read_rig_config(const std::string& path, RigConfig& config, std::string& error);

// The allowed keys, one line each with type, unit and range (for --help and README).
[[nodiscard]] std::string describe_rig_config_keys();

}  // namespace stencil::board::sherline_suzuki
