// What made an output: the program and its build, the command line, the configuration's digest and
// the tables' identity. Every report carries it as JSON and every journal as a Provenance record
// after each run's Start or Resume, so a file found on the rig box says where it came from.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace stencil::report {

struct Provenance {
  std::string program;                    // "stencil-sim"
  std::vector<std::string> command_line;  // argv as given
  std::string configuration;              // the --config file's path; "" for the compiled-in rig
  std::uint32_t configuration_crc32 = 0;  // of the file's bytes (0: compiled-in)
  std::string tables;                     // the .stbl's path, or what stands for a built-in table
  std::uint32_t tables_crc32 = 0;         // the tables' own CRC-32 (their header's)
  std::uint32_t triangle_count = 0;
};

// argv as one line a shell would take back (arguments with spaces or quotes single-quoted).
[[nodiscard]] std::string shell_line(const std::vector<std::string>& arguments);

// The report's "provenance" section: program, version, compiler, flags, command line, configuration
// {path, crc32} or "compiled-in", tables {path, crc32, triangles}.
[[nodiscard]] nlohmann::json provenance_json(const Provenance& provenance);

// The same as one line of text for the journal (at most journal::kMaxProvenanceBytes: a long command
// line is cut after a whole argument, " ..." at its end; paths and arguments quoted as a shell would
// need, a control character shown as '?'), e.g. "stencil-sim v0.3-12-gabc1234 (GNU 12.2.0); configuration compiled-in;
// tables part.stbl crc32=1a2b3c4d triangles=24; command: stencil-sim --fast".
[[nodiscard]] std::string provenance_line(const Provenance& provenance);

}  // namespace stencil::report
