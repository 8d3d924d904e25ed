#include "firmware/services/report/provenance.hpp"

#include <cstdio>

#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/report/build_version.hpp"

namespace stencil::report {
namespace {

std::string hex32(std::uint32_t value) {
  char text[12];
  std::snprintf(text, sizeof text, "%08x", value);
  return text;
}

// One line whatever an argument holds: a control character (a newline, say) shows as '?'.
std::string quoted(const std::string& raw) {
  std::string argument = raw;
  for (char& c : argument) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      c = '?';
    }
  }
  if (!argument.empty() && argument.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                                      "-_./=:,+@%") == std::string::npos) {
    return argument;
  }
  std::string out;
  out.push_back('\'');
  for (const char c : argument) {
    if (c == '\'') {
      out.append("'\\''");  // close, an escaped quote, open again
    } else {
      out.push_back(c);
    }
  }
  out.push_back('\'');
  return out;
}

}  // namespace

std::string shell_line(const std::vector<std::string>& arguments) {
  std::string line;
  for (const std::string& argument : arguments) {
    if (!line.empty()) {
      line.push_back(' ');
    }
    line.append(quoted(argument));
  }
  return line;
}

nlohmann::json provenance_json(const Provenance& p) {
  nlohmann::json configuration = "compiled-in";
  if (!p.configuration.empty()) {
    configuration = {{"path", p.configuration}, {"crc32", hex32(p.configuration_crc32)}};
  }
  return {{"program", p.program},
          {"version", source_version()},
          {"compiler", build_compiler()},
          {"flags", build_flags()},
          {"command_line", p.command_line},
          {"configuration", configuration},
          {"tables", {{"path", p.tables}, {"crc32", hex32(p.tables_crc32)}, {"triangles", p.triangle_count}}}};
}

std::string provenance_line(const Provenance& p) {
  std::string line = p.program + " " + source_version() + " (" + build_compiler() + "); configuration " +
                     (p.configuration.empty() ? std::string("compiled-in")
                                              : quoted(p.configuration) + " crc32=" + hex32(p.configuration_crc32)) +
                     "; tables " + quoted(p.tables) + " crc32=" + hex32(p.tables_crc32) +
                     " triangles=" + std::to_string(p.triangle_count) + "; command:";
  // Whole arguments only, so what is there is still what a shell would split; " ..." says more was.
  constexpr std::size_t kMost = journal::kMaxProvenanceBytes;
  constexpr std::size_t kMore = 4;  // " ..."
  for (const std::string& argument : p.command_line) {
    const std::string word = quoted(argument);
    if (line.size() + 1 + word.size() + kMore > kMost) {
      line += " ...";
      break;
    }
    line.push_back(' ');
    line.append(word);
  }
  if (line.size() > kMost) {  // a program name or paths beyond any reason
    line.resize(kMost);
  }
  return line;
}

}  // namespace stencil::report
