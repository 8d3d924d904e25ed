#include "firmware/services/gcode/gcode_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace stencil::gcode {

namespace {

// A number as G-code takes it: 5 decimals, no trailing zeros, no "-0".
std::string number(double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.5f", value);
  std::string s(text);
  while (!s.empty() && s.back() == '0') {
    s.pop_back();
  }
  if (!s.empty() && s.back() == '.') {
    s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

// The axis words that differ from `at` (all three when `all`).
std::string axis_words(const Eigen::Vector3d& to, const Eigen::Vector3d& at, bool all) {
  static constexpr char kAxes[3] = {'X', 'Y', 'Z'};
  std::string words;
  for (int i = 0; i < 3; ++i) {
    if (all || number(to[i]) != number(at[i])) {
      words.append(words.empty() ? "" : " ").append(1, kAxes[i]).append(number(to[i]));
    }
  }
  return words;
}

// G-code comments do not nest: a parenthesis inside one (a path, a tool's name) would end it early or
// be refused ("Nested comment found").
std::string comment(const std::string& text) {
  std::string out = "(";
  for (const char c : text) {
    out.push_back(c == '(' ? '[' : c == ')' ? ']' : (c == '\n' || c == '\r') ? ' ' : c);
  }
  return out + ")";
}

}  // namespace

bool write_program(std::FILE* out, const std::vector<CutMove>& moves, const Eigen::Vector3d& start_mm,
                   const ProgramSettings& settings) {
  bool ok = std::fprintf(out, "%%\n") > 0;
  for (const std::string& line : settings.comments) {
    ok = ok && std::fprintf(out, "%s\n", comment(line).c_str()) > 0;
  }
  ok = ok && std::fprintf(out, "G21 G90 G94 G17 G40 G49 G54 G61\n") > 0;
  ok = ok && std::fprintf(out, "T1 M6 %s\n", comment(settings.tool).c_str()) > 0;
  ok = ok && std::fprintf(out, "S%s M3\n", number(settings.spindle_rpm).c_str()) > 0;
  // Where the program starts, the machine's position is not known: straight up to the safe height
  // first, then over to the path's start.
  const char* g0 = settings.motion_prefix.empty() ? "G0" : "G53 G0";
  const char* g1 = settings.motion_prefix.empty() ? "G1" : "G53 G1";
  ok = ok && std::fprintf(out, "%s Z%s\n", g0, number(settings.safe_z_mm).c_str()) > 0;
  Eigen::Vector3d at(start_mm.x(), start_mm.y(), settings.safe_z_mm);
  ok = ok && std::fprintf(out, "%s X%s Y%s\n", g0, number(at.x()).c_str(), number(at.y()).c_str()) > 0;
  if (number(start_mm.z()) != number(at.z())) {
    ok = ok && std::fprintf(out, "%s Z%s\n", g0, number(start_mm.z()).c_str()) > 0;
  }
  at = start_mm;
  double feed = -1.0;
  for (const CutMove& move : moves) {
    const std::string words = axis_words(move.to_mm, at, false);
    if (words.empty()) {
      continue;  // shorter than the written precision
    }
    if (move.kind == MoveKind::Traverse) {
      ok = ok && std::fprintf(out, "%s %s\n", g0, words.c_str()) > 0;
    } else {
      const double length = (move.to_mm - at).norm();
      const double wanted = std::max(settings.min_feed_mm_per_min,
                                     move.seconds > 0.0 ? 60.0 * length / move.seconds : settings.min_feed_mm_per_min);
      std::string line = std::string(g1) + " " + words;
      if (feed < 0.0 || std::abs(wanted - feed) > 0.01 * feed) {
        feed = std::round(wanted * 10.0) / 10.0;
        line += " F" + number(std::max(feed, settings.min_feed_mm_per_min));
      }
      ok = ok && std::fprintf(out, "%s\n", line.c_str()) > 0;
    }
    at = move.to_mm;
  }
  ok = ok && std::fprintf(out, "%s Z%s\n", g0, number(settings.safe_z_mm).c_str()) > 0;
  ok = ok && std::fprintf(out, "M5\nM2\n%%\n") > 0;
  return ok;
}

}  // namespace stencil::gcode
