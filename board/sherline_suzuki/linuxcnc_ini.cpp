#include "board/sherline_suzuki/linuxcnc_ini.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace stencil::board::sherline_suzuki {
namespace {

constexpr std::size_t kMaxBytes = 1U << 20;  // an INI is a few kB
constexpr const char* kAxisSections[3] = {"AXIS_X", "AXIS_Y", "AXIS_Z"};

struct Entry {
  std::string_view section;
  std::string_view key;
  std::string_view value;
  long line;
};

struct Header {
  std::string_view name;
  long line;  // its first header
};

// The file's KEY = VALUE lines and section headers, views into its text.
struct Lines {
  std::vector<Entry> entries;
  std::vector<Header> headers;
};

std::string at(const std::string& source, long line) { return source + ":" + std::to_string(line) + ": "; }

// Text from the file as a message shows it: quoted, printable ASCII (others as '?'), at most 40 characters.
std::string shown(std::string_view text) {
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += c >= 0x20 && c < 0x7F ? static_cast<char>(c) : '?';
  }
  return out + (text.size() > 40 ? "...'" : "'");
}

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && blank(text.back())) text.remove_suffix(1);
  return text;
}

bool split_lines(std::string_view text, const std::string& source, Lines& lines, std::string& error) {
  std::string_view section;
  long line = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view content = trimmed(text.substr(start, end - start));
    start = end + 1;
    ++line;
    if (content.empty()) continue;
    if (content.front() == '#' || content.front() == ';') {
      if (content.rfind("#INCLUDE", 0) == 0) {
        error = at(source, line) + "#INCLUDE: expected every value in this file (the linuxcnc script expands " +
                "#INCLUDE into a copy of its own, NAME.expanded: give machine.linuxcnc.ini that file)";
        return false;
      }
      continue;
    }
    if (content.front() == '[') {
      // LinuxCNC looks for "[NAME]" itself: "[ NAME ]" is another section to it, so not read here either.
      const std::size_t close = content.find(']');
      const std::string_view name = close == std::string_view::npos ? std::string_view{} : content.substr(1, close - 1);
      if (close == std::string_view::npos || close + 1 != content.size() || name.empty() || trimmed(name) != name) {
        error = at(source, line) + shown(content) + ": expected a section header, [NAME] (no blanks in the brackets)";
        return false;
      }
      section = name;
      bool seen = false;
      for (const Header& header : lines.headers) seen = seen || header.name == name;
      if (!seen) lines.headers.push_back({name, line});
      continue;
    }
    const std::size_t equals = content.find('=');
    if (equals == std::string_view::npos) {
      error = at(source, line) + shown(content) + ": expected KEY = VALUE, a [SECTION] header or a comment (# or ;)";
      return false;
    }
    const std::string_view key = trimmed(content.substr(0, equals));
    if (key.empty()) {
      error = at(source, line) + shown(content) + ": expected a key before '='";
      return false;
    }
    if (section.empty()) {
      error = at(source, line) + shown(key) + ": expected a [SECTION] header before the first key";
      return false;
    }
    lines.entries.push_back({section, key, trimmed(content.substr(equals + 1)), line});
  }
  return true;
}

// "[SECTION] KEY" as messages name it.
std::string named(std::string_view section, std::string_view key) {
  return "[" + std::string(section) + "] " + std::string(key);
}

// [section] key: null when the file does not give it; false with `error` when it gives it twice
// (LinuxCNC would take the first: which one was meant is not for this reader to guess).
bool find(const Lines& lines, const std::string& source, std::string_view section, std::string_view key,
          const Entry*& found, std::string& error) {
  found = nullptr;
  for (const Entry& entry : lines.entries) {
    if (entry.section != section || entry.key != key) continue;
    if (found != nullptr) {
      error = at(source, entry.line) + named(section, key) + ": given again (first on line " +
              std::to_string(found->line) + "): expected it once";
      return false;
    }
    found = &entry;
  }
  return true;
}

std::string missing(const Lines& lines, const std::string& source, std::string_view section, std::string_view key,
                    const std::string& expected) {
  for (const Header& header : lines.headers) {
    if (header.name == section) {
      return at(source, header.line) + "[" + std::string(section) + "]: missing " + std::string(key) + ": expected " +
             expected;
    }
  }
  return source + ": no [" + std::string(section) + "] section: missing " + std::string(key) + ": expected " + expected;
}

// A decimal number, all of `text`: false for anything else (a trailing comment, a unit, nan, inf).
bool decimal(std::string_view text, double& number) {
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && (text.front() == '+' || text.front() == '-')) return false;
  }
  const char* end = text.data() + text.size();
  const auto [stop, failure] = std::from_chars(text.data(), end, number, std::chars_format::general);
  return failure == std::errc{} && stop == end && std::isfinite(number);
}

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

struct Range {
  double low;
  bool low_included;
  double high;
  const char* meaning;  // its unit and what it is
};

std::string expected_of(const Range& range) {
  return std::string(range.meaning) + ", " + (range.low_included ? "from " : "above ") + number_text(range.low) +
         (range.low_included ? " to " : ", at most ") + number_text(range.high);
}

const Range kVelocity{0.0, false, 10000.0, "mm/s, the axis's top speed"};
const Range kAcceleration{0.0, false, 1e6, "mm/s^2, the axis's acceleration"};
const Range kLimit{-1e5, true, 1e5, "machine mm, the axis's soft limit"};
const Range kPathVelocity{0.0, false, 10000.0, "mm/s, the tool path's top speed"};

bool read_number(const Lines& lines, const std::string& source, std::string_view section, std::string_view key,
                 bool required, const Range& range, IniNumber& out, std::string& error) {
  const Entry* entry = nullptr;
  if (!find(lines, source, section, key, entry, error)) return false;
  if (entry == nullptr) {
    if (required) error = missing(lines, source, section, key, expected_of(range));
    return !required;
  }
  double number = 0.0;
  if (!decimal(entry->value, number)) {
    error = at(source, entry->line) + named(section, key) + ": " + shown(entry->value) + " is not a number: expected " +
            expected_of(range) + " (nothing after the number: LinuxCNC reads no comment there)";
    return false;
  }
  if (!(range.low_included ? number >= range.low : number > range.low) || !(number <= range.high)) {
    error = at(source, entry->line) + named(section, key) + ": " + number_text(number) + " is out of range: expected " +
            expected_of(range);
    return false;
  }
  out = {number, entry->line};
  return true;
}

bool read_units(const Lines& lines, const std::string& source, std::string& error) {
  const Entry* entry = nullptr;
  if (!find(lines, source, "TRAJ", "LINEAR_UNITS", entry, error)) return false;
  const char* expected = "mm or metric (the rig's planner and the link command millimetres)";
  if (entry == nullptr) {
    error = missing(lines, source, "TRAJ", "LINEAR_UNITS", expected);
    return false;
  }
  if (entry->value != "mm" && entry->value != "metric") {
    error = at(source, entry->line) + "[TRAJ] LINEAR_UNITS: " + shown(entry->value) + ": expected " + expected;
    return false;
  }
  return true;
}

// A template's @NAME@ (sim/linuxcnc_mill/mill.ini's, before linuxcnc-sim.sh fills it in), alone or
// after an option's '='.
bool holds_placeholder(std::string_view word) {
  const auto placeholder = [](std::string_view text) { return text.size() > 2 && text.front() == '@' && text.back() == '@'; };
  const std::size_t equals = word.find('=');
  return placeholder(word) || (equals != std::string_view::npos && placeholder(word.substr(equals + 1)));
}

// linuxcncrsh's options that take a value (its getopt_long table): what the rig checks, and the
// others, whose values are skipped over.
struct Option {
  std::string_view long_name;
  char short_name;
  std::string_view value;
  bool given;
};

// words[i] as one of `options` (--long VALUE, --long=VALUE, -s VALUE or -sVALUE), its value taken and
// i moved past it. False when it is none of them; `error` set when it has no value or is given twice.
bool take_option(const std::vector<std::string_view>& words, std::size_t& i, std::array<Option, 6>& options,
                 const std::string& where, std::string& error) {
  const std::string_view word = words[i];
  for (Option& option : options) {
    const std::string long_form = "--" + std::string(option.long_name);
    const char short_form[3] = {'-', option.short_name, '\0'};
    std::string_view value;
    if (word == long_form || word == short_form) {
      if (i + 1 < words.size()) value = words[++i];
    } else if (word.rfind(long_form + "=", 0) == 0) {
      value = word.substr(long_form.size() + 1);
    } else if (word.size() > 2 && word.rfind(short_form, 0) == 0) {
      value = word.substr(2);
    } else {
      continue;
    }
    if (value.empty()) {
      error = where + long_form + " has no value: expected " + long_form + " VALUE";
    } else if (option.given) {
      error = where + long_form + " is given twice: expected it once";
    }
    option.value = value;
    option.given = true;
    return true;
  }
  return false;
}

bool read_display(const Lines& lines, const std::string& source, LinuxcncrshOptions& options, std::string& error) {
  const Entry* entry = nullptr;
  if (!find(lines, source, "DISPLAY", "DISPLAY", entry, error)) return false;
  const char* expected = "linuxcncrsh and its options (DISPLAY = linuxcncrsh --port 5007 --connectpw WORD --enablepw "
                         "WORD: the rig commands LinuxCNC through it)";
  if (entry == nullptr) {
    error = missing(lines, source, "DISPLAY", "DISPLAY", expected);
    return false;
  }
  const std::string where = at(source, entry->line) + "[DISPLAY] DISPLAY: ";
  std::vector<std::string_view> words;
  std::string_view rest = entry->value;
  while (!(rest = trimmed(rest)).empty()) {
    std::size_t end = 0;
    while (end < rest.size() && !blank(rest[end])) ++end;
    words.push_back(rest.substr(0, end));
    rest.remove_prefix(end);
  }
  const std::string_view first = words.empty() ? std::string_view{} : words[0];
  const std::size_t slash = first.rfind('/');
  if (first.substr(slash == std::string_view::npos ? 0 : slash + 1) != "linuxcncrsh") {
    error = where + "runs " + shown(first) + ": expected " + expected;
    return false;
  }
  std::array<Option, 6> linuxcncrsh{{{"port", 'p', {}, false},
                                     {"connectpw", 'w', {}, false},
                                     {"enablepw", 'e', {}, false},
                                     {"name", 'n', {}, false},
                                     {"sessions", 's', {}, false},
                                     {"path", 'd', {}, false}}};
  const Option& port = linuxcncrsh[0];
  const Option& connect = linuxcncrsh[1];
  const Option& enable = linuxcncrsh[2];
  // Up to "--": what follows it is LinuxCNC's, not linuxcncrsh's.
  for (std::size_t i = 1; i < words.size() && words[i] != "--" && error.empty(); ++i) {
    if (holds_placeholder(words[i])) {
      error = where + shown(words[i]) + " is a template's placeholder: expected the INI LinuxCNC runs with " +
              "(sim/linuxcnc_mill's linuxcnc-sim.sh start DIR fills its template into DIR/mill.ini)";
      return false;
    }
    if (take_option(words, i, linuxcncrsh, where, error) && error.empty() && holds_placeholder(words[i])) {
      error = where + shown(words[i]) + " is a template's placeholder: expected the INI LinuxCNC runs with " +
              "(sim/linuxcnc_mill's linuxcnc-sim.sh start DIR fills its template into DIR/mill.ini)";
    }
  }
  if (!error.empty()) return false;
  if (!connect.given || !enable.given) {
    const char* option = !connect.given ? "--connectpw" : "--enablepw";
    const char* fallback = !connect.given ? "EMC" : "EMCTOO";
    error = where + "no " + option + ": linuxcncrsh would take its default password " + fallback +
            ", which anyone who reaches its port knows (it listens on every interface): expected " + option +
            " with the rig's own";
    return false;
  }
  if (connect.value == "EMC" || enable.value == "EMCTOO") {
    error = where + (connect.value == "EMC" ? "--connectpw EMC" : "--enablepw EMCTOO") +
            " is linuxcncrsh's default, which anyone who reaches its port knows: expected a password of the rig's own";
    return false;
  }
  options = LinuxcncrshOptions{};
  options.line = entry->line;
  if (port.given) {
    unsigned value = 0;
    const char* end = port.value.data() + port.value.size();
    const auto [stop, failure] = std::from_chars(port.value.data(), end, value);
    if (failure != std::errc{} || stop != end || value < 1 || value > 65535) {
      error = where + "--port " + shown(port.value) + ": expected a port from 1 to 65535";
      return false;
    }
    options.port = static_cast<std::uint16_t>(value);
  }
  options.connect_password = std::string(connect.value);
  options.enable_password = std::string(enable.value);
  return true;
}

}  // namespace

bool parse_linuxcnc_ini(std::string_view text, const std::string& source, LinuxcncIni& ini, std::string& error) {
  Lines lines;
  if (!split_lines(text, source, lines, error)) return false;
  LinuxcncIni read;
  read.source = source;
  if (!read_units(lines, source, error)) return false;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    LinuxcncIniAxis& a = read.axes[axis];
    const char* section = kAxisSections[axis];
    if (!read_number(lines, source, section, "MAX_VELOCITY", true, kVelocity, a.max_velocity_mm_per_s, error) ||
        !read_number(lines, source, section, "MAX_ACCELERATION", true, kAcceleration, a.max_acceleration_mm_per_s2, error) ||
        !read_number(lines, source, section, "MIN_LIMIT", true, kLimit, a.min_limit_mm, error) ||
        !read_number(lines, source, section, "MAX_LIMIT", true, kLimit, a.max_limit_mm, error)) {
      return false;
    }
    if (!(a.min_limit_mm.value < a.max_limit_mm.value)) {
      error = at(source, a.max_limit_mm.line) + named(section, "MAX_LIMIT") + " " + number_text(a.max_limit_mm.value) +
              ": expected above MIN_LIMIT " + number_text(a.min_limit_mm.value) + " (line " +
              std::to_string(a.min_limit_mm.line) + ")";
      return false;
    }
  }
  if (!read_number(lines, source, "TRAJ", "MAX_LINEAR_VELOCITY", false, kPathVelocity, read.max_linear_velocity_mm_per_s,
                   error) ||
      !read_display(lines, source, read.display, error)) {
    return false;
  }
  read.size = text.size();
  read.crc32 = static_cast<std::uint32_t>(
      ::crc32(::crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(text.data()), static_cast<uInt>(text.size())));
  ini = std::move(read);
  return true;
}

bool read_linuxcnc_ini(const std::string& path, LinuxcncIni& ini, std::string& error) {
  // Non-blocking: a FIFO given as the INI is refused below instead of waiting for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) {
    error = path + ": cannot be opened (" + std::strerror(errno) + "): expected LinuxCNC's INI file";
    return false;
  }
  struct stat status {};
  std::string text;
  bool ok = ::fstat(fd, &status) == 0 && S_ISREG(status.st_mode);
  if (!ok) {
    error = path + ": not a regular file: expected LinuxCNC's INI file";
  }
  while (ok && text.size() <= kMaxBytes) {
    char chunk[4096];
    const ssize_t got = ::read(fd, chunk, sizeof chunk);
    if (got < 0) {
      error = path + ": could not be read (" + std::strerror(errno) + ")";
      ok = false;
    } else if (got == 0) {
      break;
    } else {
      text.append(chunk, static_cast<std::size_t>(got));
    }
  }
  ::close(fd);
  if (ok && text.size() > kMaxBytes) {
    error = path + ": over 1 MiB: expected LinuxCNC's INI file";
    ok = false;
  }
  return ok && parse_linuxcnc_ini(text, path, ini, error);
}

std::string linuxcnc_travel_outside_limits(const LinuxcncIni& ini, const std::array<double, 3>& travel_mm) {
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const LinuxcncIniAxis& a = ini.axes[axis];
    const std::string workspace = "machine.travel_mm's " + std::string(1, static_cast<char>('x' + axis)) + " [0, " +
                                  number_text(travel_mm[axis]) + "] (machine mm, 0 at home)";
    if (a.min_limit_mm.value > 0.0) {
      return at(ini.source, a.min_limit_mm.line) + named(kAxisSections[axis], "MIN_LIMIT") + " " +
             number_text(a.min_limit_mm.value) + " cuts into " + workspace + ": expected at most 0";
    }
    if (a.max_limit_mm.value < travel_mm[axis]) {
      return at(ini.source, a.max_limit_mm.line) + named(kAxisSections[axis], "MAX_LIMIT") + " " +
             number_text(a.max_limit_mm.value) + " cuts into " + workspace + ": expected at least " +
             number_text(travel_mm[axis]) + " (LinuxCNC would refuse a move there), or a smaller travel";
    }
  }
  return "";
}

std::string linuxcnc_display_disagreement(const LinuxcncIni& ini, std::uint16_t port, std::string_view connect_password,
                                          std::string_view enable_password) {
  const std::string where = at(ini.source, ini.display.line) + "[DISPLAY] DISPLAY: ";
  if (ini.display.port != port) {
    return where + "linuxcncrsh listens on port " + std::to_string(ini.display.port) +
           ", machine.linuxcnc.port is " + std::to_string(port) + ": expected the same port";
  }
  if (ini.display.connect_password != connect_password) {
    return where + "--connectpw differs from machine.linuxcnc.connect_password: expected the same password " +
           "(linuxcncrsh would answer the rig's hello with HELLO NAK)";
  }
  if (ini.display.enable_password != enable_password) {
    return where + "--enablepw differs from machine.linuxcnc.enable_password: expected the same password " +
           "(linuxcncrsh would refuse the rig's set enable)";
  }
  return "";
}

}  // namespace stencil::board::sherline_suzuki
