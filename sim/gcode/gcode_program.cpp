// A G-code program read through LinuxCNC's rs274 (batch mode): block numbering, running the
// interpreter, and reading its canonical calls into moves. What rs274 does was established by
// experiment with linuxcnc-uspace 2.9.0~pre1 (Debian 12); each fact is noted where it is used.
#include "sim/gcode/gcode_program.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string_view>
#include <thread>

namespace stencil::sim {
namespace {

constexpr double kMmPerInch = 25.4;

// ---- number_blocks -------------------------------------------------------------------------------

void append_numbered(std::string& out, std::string_view text, int line) {
  std::size_t i = 0;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
  // A '%' line delimits the program and may carry nothing else (rs274: "Bad character '%' used").
  if (i < text.size() && text[i] == '%') {
    out.append(text);
    return;
  }
  // rs274 wants a block delete '/' before the N word ("N6 /G1" is "Bad character '/' used").
  const bool block_delete = i < text.size() && text[i] == '/';
  if (block_delete) {
    ++i;
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
  }
  // rs274 drops spaces inside words and takes "n 1 2" for N12 and "N13.5" for N13; a second N word
  // in a block is "Bad character 'n' used", so the old one goes, whatever its spelling.
  if (i < text.size() && (text[i] == 'N' || text[i] == 'n')) {
    ++i;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) != 0 || text[i] == ' ' ||
                               text[i] == '\t' || text[i] == '.')) {
      ++i;
    }
  }
  const std::string_view rest = text.substr(i);
  // The marker must be the line's last parenthesised comment (rs274 emits only the last one) and
  // may not come before an O word ("Bad character 'o' used"): so at the end, before a ';' comment
  // (a ';' inside parentheses is part of that comment).
  std::size_t insert_at = rest.size();
  bool in_comment = false;
  for (std::size_t j = 0; j < rest.size(); ++j) {
    if (rest[j] == '(') {
      in_comment = true;
    } else if (rest[j] == ')') {
      in_comment = false;
    } else if (rest[j] == ';' && !in_comment) {
      insert_at = j;
      break;
    }
  }
  if (block_delete) out += '/';
  out += 'N';
  out += std::to_string(line);
  out += ' ';
  out.append(rest.substr(0, insert_at));
  out += '(';
  out += kGcodeBlockMarker;
  out += ')';
  out.append(rest.substr(insert_at));
}

// ---- parse_canonical -----------------------------------------------------------------------------

// One line of rs274's batch output: "   26 N10    STRAIGHT_FEED(1.0000, ...)". The N field is
// "N....." for a block with no N word, and printed "%-6d"-wide, so N100000 runs into the name
// ("N100000SET_FEED_RATE(10.0000)").
struct CanonicalCall {
  int output_line = 0;  // 1-based line of rs274's output
  int source_line = 0;  // the block's N word, 0 when it had none
  std::string_view name;
  std::string_view arguments;  // between the parentheses
};

std::string printable(std::string_view text) {
  std::string shown;
  for (const char c : text.substr(0, 80)) {
    shown += std::isprint(static_cast<unsigned char>(c)) != 0 ? c : '?';
  }
  if (text.size() > 80) shown += "...";
  return shown;
}

bool read_digits(std::string_view text, std::size_t& i, int& value) {
  const std::size_t start = i;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) != 0) ++i;
  if (i == start) return false;
  const auto [end, status] = std::from_chars(text.data() + start, text.data() + i, value);
  return status == std::errc() && end == text.data() + i;
}

// False when the line is not a canonical call; source_line is filled as far as it could be read.
bool split_call(std::string_view text, CanonicalCall& call) {
  std::size_t i = 0;
  while (i < text.size() && text[i] == ' ') ++i;
  int output_number = 0;
  if (!read_digits(text, i, output_number)) return false;
  if (i >= text.size() || text[i] != ' ') return false;
  while (i < text.size() && text[i] == ' ') ++i;
  if (i >= text.size() || text[i] != 'N') return false;
  ++i;
  if (text.substr(i, 5) == ".....") {
    i += 5;
  } else if (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) != 0) {
    if (!read_digits(text, i, call.source_line) || call.source_line < 1) {
      call.source_line = 0;
      return false;
    }
  }
  while (i < text.size() && text[i] == ' ') ++i;
  const std::size_t name_start = i;
  while (i < text.size() && (std::isupper(static_cast<unsigned char>(text[i])) != 0 ||
                             std::isdigit(static_cast<unsigned char>(text[i])) != 0 || text[i] == '_')) {
    ++i;
  }
  if (i == name_start || i >= text.size() || text[i] != '(') return false;
  call.name = text.substr(name_start, i - name_start);
  std::size_t close = text.size();
  while (close > i + 1 && text[close - 1] == ' ') --close;
  if (text[close - 1] != ')' || close - 1 <= i) return false;
  call.arguments = text.substr(i + 1, close - 2 - i);
  return true;
}

enum class NumbersRead : std::uint8_t { Ok, Malformed, NotFinite };

// The arguments as numbers: rs274 separates them by ", " and some by a bare space
// ("USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 12.9794, ...)", "SET_SPINDLE_MODE(0 0.0000)").
NumbersRead read_numbers(std::string_view arguments, std::vector<double>& numbers) {
  numbers.clear();
  std::size_t i = 0;
  while (true) {
    while (i < arguments.size() && (arguments[i] == ' ' || arguments[i] == ',')) ++i;
    if (i >= arguments.size()) return NumbersRead::Ok;
    double value = 0.0;
    const auto [end, status] = std::from_chars(arguments.data() + i, arguments.data() + arguments.size(), value);
    if (status != std::errc()) {
      // from_chars refuses out-of-range text ("1e999") rather than giving infinity: not finite.
      return status == std::errc::result_out_of_range ? NumbersRead::NotFinite : NumbersRead::Malformed;
    }
    i = static_cast<std::size_t>(end - arguments.data());
    if (i < arguments.size() && arguments[i] != ' ' && arguments[i] != ',') return NumbersRead::Malformed;
    // printf prints NaN and infinity as "nan"/"inf", which from_chars reads back.
    if (!std::isfinite(value)) return NumbersRead::NotFinite;
    numbers.push_back(value);
  }
}

enum class Plane : std::uint8_t { XY, YZ, XZ };

// ARC_FEED(first_end, second_end, first_centre, second_centre, rotation, axis_end, a, b, c) names
// the axes of the selected plane in right-handed order: XY -> (X, Y; Z), YZ -> (Y, Z; X),
// XZ -> (Z, X; Y) (checked: G18 G2 X5 Z3 I2 K-1 from X1 Z3 prints ARC_FEED(3, 5, 2, 3, -1, y)).
// The rotation's sign is counter-clockwise positive from the first axis to the second (G3 +1,
// G2 -1 in every plane); |rotation| - 1 is the number of extra full turns (G2 ... P2 prints -2).
struct PlaneAxes {
  int first;
  int second;
  int axis;
};
PlaneAxes axes_of(Plane plane) {
  switch (plane) {
    case Plane::XY: return {0, 1, 2};
    case Plane::YZ: return {1, 2, 0};
    case Plane::XZ: return {2, 0, 1};
  }
  return {0, 1, 2};
}

class CanonicalReader {
 public:
  CanonicalReader(const GcodeReadOptions& options, GcodeProgram& program, std::string& error)
      : options_(options), program_(program), error_(error) {}

  bool read(std::string_view output) {
    if (!std::isfinite(options_.arc_tolerance_mm) || options_.arc_tolerance_mm <= 0.0) {
      error_ = "the arc tolerance must be a positive number of mm (got " + std::to_string(options_.arc_tolerance_mm) + ")";
      return false;
    }
    int output_line = 0;
    std::size_t start = 0;
    while (start < output.size()) {
      std::size_t end = output.find('\n', start);
      if (end == std::string_view::npos) end = output.size();
      std::string_view text = output.substr(start, end - start);
      start = end + 1;
      ++output_line;
      if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
      if (text.find_first_not_of(" \t") == std::string_view::npos) continue;
      CanonicalCall call;
      call.output_line = output_line;
      if (!split_call(text, call)) {
        return fail(call, "cannot read rs274's output \"" + printable(text) + "\"");
      }
      if (!take(call)) return false;
    }
    if (program_.moves.empty()) {
      error_ = "the program makes no move";
      return false;
    }
    return true;
  }

 private:
  bool fail(const CanonicalCall& call, const std::string& what) {
    error_ = call.source_line > 0 ? "line " + std::to_string(call.source_line) + ": " + what
                                  : "canonical output line " + std::to_string(call.output_line) + ": " + what;
    return false;
  }
  bool refuse(const CanonicalCall& call, const std::string& what) {
    return fail(call, what + ": the guard cannot follow it faithfully (" + std::string(call.name) + ")");
  }

  bool numbers(const CanonicalCall& call, std::size_t count_min, std::size_t count_max) {
    switch (read_numbers(call.arguments, numbers_)) {
      case NumbersRead::Ok: break;
      case NumbersRead::Malformed:
        return fail(call, "cannot read the numbers of " + std::string(call.name) + "(" + printable(call.arguments) + ")");
      case NumbersRead::NotFinite:
        return fail(call, std::string(call.name) + " has a number that is not finite (" + printable(call.arguments) + ")");
    }
    if (numbers_.size() < count_min || numbers_.size() > count_max) {
      return fail(call, std::string(call.name) + " has " + std::to_string(numbers_.size()) + " numbers, expected " +
                            std::to_string(count_min) +
                            (count_max != count_min ? " to " + std::to_string(count_max) : std::string()));
    }
    return true;
  }

  // rs274 prints tool numbers as integers; anything else is not its output (and would not convert).
  bool tool_number(const CanonicalCall& call) {
    if (numbers_[0] >= 0.0 && numbers_[0] <= 1e9 && numbers_[0] == std::round(numbers_[0])) return true;
    return fail(call, "a tool number that is not a whole number from 0 (" + printable(call.arguments) + ")");
  }

  bool all_zero(std::size_t from) const {
    return std::all_of(numbers_.begin() + static_cast<std::ptrdiff_t>(from), numbers_.end(),
                       [](double v) { return v == 0.0; });
  }

  bool take(const CanonicalCall& call) {
    const std::string_view name = call.name;
    if (name == "STRAIGHT_TRAVERSE" || name == "STRAIGHT_FEED" || name == "ARC_FEED") return take_move(call);
    if (name == "COMMENT") return take_comment(call);
    if (name == "USE_LENGTH_UNITS") {
      if (call.arguments == "CANON_UNITS_MM") {
        mm_per_unit_ = 1.0;
      } else if (call.arguments == "CANON_UNITS_INCHES") {
        mm_per_unit_ = kMmPerInch;  // coordinates and feeds are printed in the current units
      } else {
        return refuse(call, "unknown length units " + printable(call.arguments));
      }
      return true;
    }
    if (name == "SELECT_PLANE") {
      if (call.arguments == "CANON_PLANE_XY") {
        plane_ = Plane::XY;
      } else if (call.arguments == "CANON_PLANE_YZ") {
        plane_ = Plane::YZ;
      } else if (call.arguments == "CANON_PLANE_XZ") {
        plane_ = Plane::XZ;
      } else {
        return refuse(call, "the plane " + printable(call.arguments));
      }
      return true;
    }
    if (name == "SET_FEED_RATE") {
      if (!numbers(call, 1, 1)) return false;
      if (numbers_[0] < 0.0) return fail(call, "a negative feed rate");
      // LinuxCNC's canon converts a feed to its own units when it is set (FROM_PROG_LEN in
      // SET_FEED_RATE), and rs274 does not print the feed again when G20/G21 change: so the units
      // at this call are the feed's.
      feed_mm_per_min_ = numbers_[0] * mm_per_unit_;
      return true;
    }
    if (name == "SET_FEED_MODE") {
      // rs274 prints SET_FEED_MODE(spindle, mode): 1 after G95 (per revolution); G93 prints 0 as
      // G94 does, and is told by its interpreter comment (take_comment).
      if (!numbers(call, 1, 2)) return false;
      if (numbers_.back() != 0.0) return refuse(call, "feed per revolution (G95)");
      return true;
    }
    if (name == "SET_G5X_OFFSET") {
      // Canonical coordinates are the program's own: G10 L2 P1 X10 and G92 leave G1 X1 printed as
      // X1 (LinuxCNC's canon adds the offsets on the machine side). An offset set by the program
      // moves the work relative to the machine mid-program; the guard takes the program's
      // coordinates as the work's, so only zero offsets are followed.
      if (!numbers(call, 7, 10)) return false;
      if (!all_zero(1)) return refuse(call, "a non-zero work offset (G10 L2/L20 on G54..G59.3)");
      return true;
    }
    if (name == "SET_G92_OFFSET") {
      if (!numbers(call, 6, 9)) return false;
      if (!all_zero(0)) return refuse(call, "a non-zero G92/G52 offset");
      return true;
    }
    if (name == "SET_XY_ROTATION") {
      // Unlike the offsets, the rotation is applied to the printed coordinates (G10 L2 R30 turns
      // G1 X3 into STRAIGHT_FEED(3.0000, 1.2321, ...)); refused all the same, it moves the work.
      if (!numbers(call, 1, 1)) return false;
      if (numbers_[0] != 0.0) return refuse(call, "an XY rotation of the coordinate system (G10 L2 R)");
      return true;
    }
    if (name == "USE_TOOL_LENGTH_OFFSET") {
      // The offset is subtracted from the printed Z (G43 H1 with a 12.9794 offset prints G1 Z5 as
      // Z-7.9794): the tip of the guard's tool would no longer be the program's Z.
      if (!numbers(call, 1, 9)) return false;
      if (!all_zero(0)) return refuse(call, "a non-zero tool length offset (G43/G43.1/G43.2)");
      return true;
    }
    if (name == "SELECT_TOOL") {
      if (!numbers(call, 1, 1) || !tool_number(call)) return false;
      if (program_.moves.empty()) program_.tool = "T" + std::to_string(static_cast<long long>(numbers_[0]));
      return true;
    }
    if (name == "CHANGE_TOOL" || name == "CHANGE_TOOL_NUMBER") {
      // One before the first move is the tool being loaded (its number came with SELECT_TOOL or
      // is the argument of M61's CHANGE_TOOL_NUMBER); one after it is a second tool the stencil
      // was not made for.
      if (!program_.moves.empty()) return refuse(call, "a tool change after the first move (M6/M61)");
      if (name == "CHANGE_TOOL_NUMBER") {
        if (!numbers(call, 1, 1) || !tool_number(call)) return false;
        program_.tool = "T" + std::to_string(static_cast<long long>(numbers_[0]));
      }
      return true;
    }
    if (name == "STRAIGHT_PROBE") return refuse(call, "probing (G38.x)");
    if (name == "RIGID_TAP") return refuse(call, "rigid tapping (G33.1)");
    if (name == "START_SPEED_FEED_SYNC" || name == "START_SPEED_FEED_SYNCH") {
      return refuse(call, "spindle-synchronised motion (G33/G33.1/G76)");
    }
    if (name == "START_CUTTER_RADIUS_COMPENSATION") return refuse(call, "cutter radius compensation (G41/G42)");
    if (is_harmless(name)) return true;
    return refuse(call, "an unknown canonical call " + std::string(name));
  }

  // Calls that neither move the tool nor change the geometry of later moves.
  static bool is_harmless(std::string_view name) {
    static constexpr std::array<std::string_view, 35> kHarmless = {
        "MESSAGE", "SET_FEED_REFERENCE", "SET_TRAVERSE_RATE", "SET_MOTION_CONTROL_MODE", "SET_NAIVECAM_TOLERANCE",
        "SET_SPINDLE_SPEED", "START_SPINDLE_CLOCKWISE", "START_SPINDLE_COUNTERCLOCKWISE", "STOP_SPINDLE_TURNING",
        "SET_SPINDLE_MODE", "ORIENT_SPINDLE", "FLOOD_ON", "FLOOD_OFF", "MIST_ON", "MIST_OFF", "DWELL",
        "PROGRAM_STOP", "OPTIONAL_PROGRAM_STOP", "PROGRAM_END", "ON_RESET", "START_CHANGE",
        "ENABLE_FEED_OVERRIDE", "DISABLE_FEED_OVERRIDE", "ENABLE_SPEED_OVERRIDE", "DISABLE_SPEED_OVERRIDE",
        "ENABLE_ADAPTIVE_FEED", "DISABLE_ADAPTIVE_FEED", "ENABLE_FEED_HOLD", "DISABLE_FEED_HOLD",
        "SET_MOTION_OUTPUT_BIT", "CLEAR_MOTION_OUTPUT_BIT", "SET_AUX_OUTPUT_BIT", "CLEAR_AUX_OUTPUT_BIT",
        "SET_MOTION_OUTPUT_VALUE", "SET_AUX_OUTPUT_VALUE"};
    return std::find(kHarmless.begin(), kHarmless.end(), name) != kHarmless.end();
  }

  bool take_comment(const CanonicalCall& call) {
    std::string_view text = call.arguments;
    if (text.size() >= 2 && text.front() == '"' && text.back() == '"') text = text.substr(1, text.size() - 2);
    if (text == kGcodeBlockMarker) {
      block_line_ = call.source_line;
      block_moves_ = 0;
      return true;
    }
    // Some modes show in the canon only as the interpreter's comments: G41/G42/G41.1/G42.1 print no
    // START_CUTTER_RADIUS_COMPENSATION, just "cutter radius compensation on left|right", and then
    // print already-offset moves; G93 prints SET_FEED_MODE(0, 0) as G94 does.
    constexpr std::string_view kInterpreter = "interpreter: ";
    if (text.substr(0, kInterpreter.size()) != kInterpreter) return true;
    if (text.find("cutter radius compensation on") != std::string_view::npos) {
      return refuse(call, "cutter radius compensation (G41/G42/G41.1/G42.1)");
    }
    if (text.find("inverse time") != std::string_view::npos) return refuse(call, "inverse-time feed (G93)");
    if (text.find("units per revolution") != std::string_view::npos) return refuse(call, "feed per revolution (G95)");
    return true;
  }

  bool take_move(const CanonicalCall& call) {
    const bool arc = call.name == "ARC_FEED";
    // The rotary axes follow X, Y, Z (and the arc's axis end); some builds print U, V, W as well.
    if (!(arc ? numbers(call, 9, 12) : numbers(call, 6, 9))) return false;
    if (call.source_line == 0) return fail(call, "a move from a block with no line number (" + std::string(call.name) + ")");
    if (!all_zero(arc ? 6 : 3)) return refuse(call, "motion in A/B/C (or U/V/W)");
    // One run of a block (from its marker comment) makes at most one canonical move: rs274 expands
    // canned cycles (G73/G74/G76/G81..G89), G28/G30 and splines into several moves of the same block,
    // with nothing else to tell them apart when G61 is already active (the cycle's own switch to
    // exact path is then not printed). Without markers, consecutive moves of one line count as one run.
    if (call.source_line != block_line_) {
      block_line_ = call.source_line;
      block_moves_ = 0;
    }
    if (++block_moves_ > 1) {
      return refuse(call, "one block making several moves (a canned cycle G73/G74/G76/G81-G89, G28/G30 or a spline)");
    }
    if (call.name != "STRAIGHT_TRAVERSE" && feed_mm_per_min_ <= 0.0) {
      return fail(call, "a feed move with no feed rate (F was never set)");
    }
    if (program_.moves.size() >= kMaxGcodeMoves) {
      return fail(call, "the program makes more than " + std::to_string(kMaxGcodeMoves) + " moves");
    }
    if (arc) return take_arc(call);
    const Eigen::Vector3d to = Eigen::Vector3d(numbers_[0], numbers_[1], numbers_[2]) * mm_per_unit_;
    if (call.name == "STRAIGHT_TRAVERSE") {
      program_.moves.push_back({call.source_line, GcodeMoveKind::Traverse, to, 0.0});
    } else {
      program_.moves.push_back({call.source_line, GcodeMoveKind::Feed, to, feed_mm_per_min_});
    }
    position_mm_ = to;
    return true;
  }

  bool take_arc(const CanonicalCall& call) {
    const PlaneAxes axes = axes_of(plane_);
    const double rotation = numbers_[4];
    if (rotation == 0.0 || rotation != std::round(rotation) || std::abs(rotation) > 1e6) {
      return fail(call, "ARC_FEED's rotation must be a non-zero whole number of turns (" + printable(call.arguments) + ")");
    }
    const Eigen::Vector3d start = position_mm_;
    Eigen::Vector3d end;
    end[axes.first] = numbers_[0] * mm_per_unit_;
    end[axes.second] = numbers_[1] * mm_per_unit_;
    end[axes.axis] = numbers_[5] * mm_per_unit_;
    const Eigen::Vector2d centre(numbers_[2] * mm_per_unit_, numbers_[3] * mm_per_unit_);
    const Eigen::Vector2d from = Eigen::Vector2d(start[axes.first], start[axes.second]) - centre;
    const Eigen::Vector2d to = Eigen::Vector2d(end[axes.first], end[axes.second]) - centre;
    const double start_radius = from.norm();
    const double end_radius = to.norm();
    if (start_radius < 1e-9 || end_radius < 1e-9) return fail(call, "an arc of zero radius");
    const double start_angle = std::atan2(from.y(), from.x());
    const double end_angle = std::atan2(to.y(), to.x());
    constexpr double kTurn = 2.0 * std::numbers::pi;
    // An end on the start (the same printed numbers) is a full circle, as in LinuxCNC.
    double sweep = end_angle - start_angle;
    if (rotation > 0.0) {
      if (sweep <= 0.0) sweep += kTurn;
      sweep += (rotation - 1.0) * kTurn;
    } else {
      if (sweep >= 0.0) sweep -= kTurn;
      sweep += (rotation + 1.0) * kTurn;
    }
    // A chord over angle step d sags r (1 - cos(d / 2)) below the circle; at least four per turn.
    const double radius = std::max(start_radius, end_radius);
    double step = std::numbers::pi / 2.0;
    if (options_.arc_tolerance_mm < radius) {
      step = std::min(step, 2.0 * std::acos(1.0 - options_.arc_tolerance_mm / radius));
    }
    const double chords = std::ceil(std::abs(sweep) / step);
    if (!(chords <= static_cast<double>(kMaxGcodeMoves - program_.moves.size()))) {
      return fail(call, "the arc needs " + std::to_string(chords) + " chords at " +
                            std::to_string(options_.arc_tolerance_mm) + " mm, more than the program may make (" +
                            std::to_string(kMaxGcodeMoves) + " moves)");
    }
    const auto count = std::max<std::size_t>(1, static_cast<std::size_t>(chords));
    // The printed radii differ by the rounding of 4 decimals (and LinuxCNC tolerates a little
    // more, as a spiral): the radius goes linearly from start to end, so does the helix's axis.
    for (std::size_t k = 1; k <= count; ++k) {
      Eigen::Vector3d point = end;
      if (k < count) {
        const double t = static_cast<double>(k) / static_cast<double>(count);
        const double angle = start_angle + sweep * t;
        const double r = start_radius + (end_radius - start_radius) * t;
        point[axes.first] = centre.x() + r * std::cos(angle);
        point[axes.second] = centre.y() + r * std::sin(angle);
        point[axes.axis] = start[axes.axis] + (end[axes.axis] - start[axes.axis]) * t;
      }
      program_.moves.push_back({call.source_line, GcodeMoveKind::Feed, point, feed_mm_per_min_});
    }
    position_mm_ = end;
    return true;
  }

  const GcodeReadOptions& options_;
  GcodeProgram& program_;
  std::string& error_;
  std::vector<double> numbers_;
  double mm_per_unit_ = 1.0;  // rs274 starts in mm (its first call is USE_LENGTH_UNITS(CANON_UNITS_MM))
  Plane plane_ = Plane::XY;
  double feed_mm_per_min_ = 0.0;
  // rs274 assumes the machine at 0,0,0 when it starts: the first move (an arc too) starts there.
  Eigen::Vector3d position_mm_ = Eigen::Vector3d::Zero();
  int block_line_ = -1;
  int block_moves_ = 0;
};

// ---- running rs274 -------------------------------------------------------------------------------

bool read_file(const std::string& path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream buffer;
  buffer << in.rdbuf();
  text = buffer.str();
  return !in.bad();
}

// PATH lookup in the parent: between fork and exec only async-signal-safe calls belong.
std::string find_executable(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : std::string();
  const char* path = std::getenv("PATH");
  std::string_view folders = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  while (true) {
    const std::size_t colon = folders.find(':');
    const std::string_view folder = folders.substr(0, colon);
    const std::string candidate = (folder.empty() ? std::string(".") : std::string(folder)) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    if (colon == std::string_view::npos) return {};
    folders.remove_prefix(colon + 1);
  }
}

// Removes the temporary folder whatever happens.
struct TemporaryFolder {
  std::string path;
  ~TemporaryFolder() {
    if (path.empty()) return;
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

struct Rs274Run {
  bool started = false;
  bool timed_out = false;
  int status = 0;  // waitpid's
};

// rs274 -g program.ngc canon.txt in `folder` (so that no rs274.var, tool table or subroutine file
// of the caller's folder is read: a call of an outside subroutine is an rs274 error), stdout and
// stderr to files there, its output bounded by RLIMIT_FSIZE and its time by a deadline.
Rs274Run run_rs274(const std::string& executable, const std::string& folder, const GcodeReadOptions& options) {
  Rs274Run run;
  std::array<std::string, 4> words = {executable, "-g", "program.ngc", "canon.txt"};
  std::array<char*, 5> argv = {words[0].data(), words[1].data(), words[2].data(), words[3].data(), nullptr};
  const pid_t pid = fork();
  if (pid < 0) return run;
  if (pid == 0) {
    if (chdir(folder.c_str()) != 0) _exit(126);
    const int in = open("/dev/null", O_RDONLY);
    const int out = open("stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err = open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (in < 0 || out < 0 || err < 0 || dup2(in, 0) < 0 || dup2(out, 1) < 0 || dup2(err, 2) < 0) _exit(126);
    const rlimit size_limit = {options.max_output_bytes, options.max_output_bytes};
    if (setrlimit(RLIMIT_FSIZE, &size_limit) != 0) _exit(126);
    execv(executable.c_str(), argv.data());
    _exit(127);
  }
  run.started = true;
  const double timeout_s = std::isfinite(options.timeout_s) && options.timeout_s > 0.0 ? options.timeout_s : 30.0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (true) {
    const pid_t done = waitpid(pid, &run.status, WNOHANG);
    if (done == pid) return run;
    if (done < 0 && errno != EINTR) {
      run.started = false;
      return run;
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
      }
      run.timed_out = true;
      return run;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::string source_line_text(const std::string& source, int line) {
  std::size_t start = 0;
  for (int i = 1; i < line; ++i) {
    start = source.find('\n', start);
    if (start == std::string::npos) return {};
    ++start;
  }
  std::size_t end = source.find('\n', start);
  if (end == std::string::npos) end = source.size();
  std::string_view text(source.data() + start, end - start);
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  return printable(text);
}

// rs274's error (exit status 1) is on stderr: "executing", the message, and last the text of the
// block it failed on, as numbered ("N3 G1 X2 Q(@)"), e.g.
//   executing / No characters found in reading real value / N3 G1 X2 Q(@)
// Its output file then holds the canon up to the block before, and ON_RESET twice.
std::string rs274_error(const std::string& stderr_text, const std::string& source, int status) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < stderr_text.size()) {
    std::size_t end = stderr_text.find('\n', start);
    if (end == std::string::npos) end = stderr_text.size();
    std::string_view text(stderr_text.data() + start, end - start);
    start = end + 1;
    if (text.find_first_not_of(" \t\r") == std::string_view::npos || text == "executing") continue;
    lines.push_back(text);
  }
  const std::string exit = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                             : "signal " + std::to_string(WTERMSIG(status));
  if (lines.empty()) return "rs274 failed (" + exit + ") and said nothing";
  int line = 0;
  std::size_t i = 0;
  const std::string_view block = lines.back();
  while (i < block.size() && (block[i] == ' ' || block[i] == '\t' || block[i] == '/')) ++i;
  std::string message;
  const std::size_t message_lines = lines.size() - 1;
  if (i < block.size() && block[i] == 'N' && read_digits(block, ++i, line) && line > 0 && message_lines > 0) {
    for (std::size_t k = 0; k < message_lines; ++k) message += (k > 0 ? "; " : "") + printable(lines[k]);
    return "line " + std::to_string(line) + ": rs274: " + message + " (in \"" + source_line_text(source, line) + "\")";
  }
  for (std::size_t k = 0; k < lines.size(); ++k) message += (k > 0 ? "; " : "") + printable(lines[k]);
  return "rs274 failed (" + exit + "): " + message;
}

}  // namespace

std::string number_blocks(const std::string& source) {
  std::string out;
  out.reserve(source.size() + source.size() / 4 + 16);
  std::size_t start = 0;
  int line = 0;
  while (start < source.size()) {
    std::size_t end = source.find('\n', start);
    const std::size_t next = end == std::string::npos ? source.size() : end + 1;
    if (end == std::string::npos) end = source.size();
    std::string_view text(source.data() + start, end - start);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    append_numbered(out, text, ++line);
    out += '\n';
    start = next;
  }
  return out;
}

bool parse_canonical(const std::string& rs274_output, const GcodeReadOptions& options, GcodeProgram& program,
                     std::string& error) {
  GcodeProgram read;
  CanonicalReader reader(options, read, error);
  if (!reader.read(rs274_output)) return false;
  program = std::move(read);
  error.clear();
  return true;
}

bool read_gcode_program(const std::string& path, const GcodeReadOptions& options, GcodeProgram& program,
                        std::string& error) {
  std::string source;
  if (!read_file(path, source)) {
    error = path + ": cannot read: " + std::strerror(errno);
    return false;
  }
  const std::string executable = find_executable(options.rs274);
  if (executable.empty()) {
    error = path + ": cannot run " + options.rs274 + ": not found or not executable (linuxcnc-uspace installs rs274)";
    return false;
  }
  const char* tmp = std::getenv("TMPDIR");
  std::string folder_template = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/stencil-gcode-XXXXXX";
  TemporaryFolder folder;
  if (mkdtemp(folder_template.data()) == nullptr) {
    error = path + ": cannot make a temporary folder " + folder_template + ": " + std::strerror(errno);
    return false;
  }
  folder.path = folder_template;
  {
    std::ofstream numbered(folder.path + "/program.ngc", std::ios::binary);
    numbered << number_blocks(source);
    if (!numbered.flush()) {
      error = path + ": cannot write the numbered program into " + folder.path;
      return false;
    }
  }
  const Rs274Run run = run_rs274(executable, folder.path, options);
  if (!run.started) {
    error = path + ": cannot start " + executable + ": " + std::strerror(errno);
    return false;
  }
  if (run.timed_out) {
    error = path + ": rs274 did not finish within " + std::to_string(options.timeout_s) + " s (a loop without end?)";
    return false;
  }
  if (WIFSIGNALED(run.status) && WTERMSIG(run.status) == SIGXFSZ) {
    error = path + ": rs274's output passed " + std::to_string(options.max_output_bytes) + " bytes (a loop without end?)";
    return false;
  }
  if (WIFEXITED(run.status) && (WEXITSTATUS(run.status) == 126 || WEXITSTATUS(run.status) == 127)) {
    error = path + ": cannot run " + executable + " (exit status " + std::to_string(WEXITSTATUS(run.status)) + ")";
    return false;
  }
  if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) {
    std::string stderr_text;
    (void)read_file(folder.path + "/stderr.txt", stderr_text);
    error = path + ": " + rs274_error(stderr_text, source, run.status);
    return false;
  }
  std::string canon;
  if (!read_file(folder.path + "/canon.txt", canon)) {
    error = path + ": rs274 wrote no canonical output";
    return false;
  }
  if (!parse_canonical(canon, options, program, error)) {
    error = path + ": " + error;
    return false;
  }
  return true;
}

}  // namespace stencil::sim
