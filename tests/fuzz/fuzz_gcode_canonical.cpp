// libFuzzer target: the G-code reader's pure parts take any bytes. number_blocks keeps one line per
// input line, each numbered with its own line (or a '%' line kept); parse_canonical either names
// where it stopped or gives a program that keeps its promises (moves on numbered lines, finite end
// points, a positive feed on every feed move and none on a traverse, within the move cap).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/gcode/gcode_program.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

namespace {

void check_numbering(const std::string& source) {
  const std::string numbered = stencil::sim::number_blocks(source);
  std::size_t input_lines = 0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    if (source[i] == '\n' || i + 1 == source.size()) ++input_lines;
  }
  std::size_t line = 0;
  std::size_t start = 0;
  while (start < numbered.size()) {
    const std::size_t end = numbered.find('\n', start);
    require(end != std::string::npos);  // every line ends with its newline
    ++line;
    std::string text = numbered.substr(start, end - start);
    start = end + 1;
    const std::size_t first = text.find_first_not_of(" \t");
    if (first != std::string::npos && text[first] == '%') continue;
    if (!text.empty() && text[0] == '/') text.erase(0, 1);
    const std::string word = "N" + std::to_string(line) + " ";
    require(text.compare(0, word.size(), word) == 0);
  }
  require(line == input_lines);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  check_numbering(text);

  stencil::sim::GcodeReadOptions options;
  options.arc_tolerance_mm = 0.01;  // arcs of fuzzed radii sampled with fewer chords: more inputs a second
  stencil::sim::GcodeProgram program;
  std::string error;
  if (!stencil::sim::parse_canonical(text, options, program, error)) {
    require(!error.empty());
    require(error.rfind("line ", 0) == 0 || error.rfind("canonical output line ", 0) == 0 ||
            error == "the program makes no move");
    return 0;
  }
  require(error.empty() && !program.moves.empty() && program.moves.size() <= stencil::sim::kMaxGcodeMoves);
  for (const stencil::sim::GcodeMove& move : program.moves) {
    require(move.line >= 1 && move.to_mm.allFinite() && std::isfinite(move.feed_mm_per_min));
    if (move.kind == stencil::sim::GcodeMoveKind::Feed) {
      require(move.feed_mm_per_min > 0.0);
    } else {
      require(move.feed_mm_per_min == 0.0);
    }
  }
  return 0;
}
