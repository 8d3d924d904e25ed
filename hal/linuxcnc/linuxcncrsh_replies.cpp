// linuxcncrsh's replies: see the header.
#include "hal/linuxcnc/linuxcncrsh_replies.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

namespace stencil::hal::linuxcnc {
namespace {

// The next word of `rest` (spaces before it skipped), and `rest` after it.
std::string_view next_word(std::string_view& rest) {
  std::size_t start = 0;
  while (start < rest.size() && rest[start] == ' ') {
    ++start;
  }
  std::size_t end = start;
  while (end < rest.size() && rest[end] != ' ') {
    ++end;
  }
  // Built from pointers, not substr(): substr's range check may throw, and the core does not.
  const std::string_view word(rest.data() + start, end - start);
  rest = std::string_view(rest.data() + end, rest.size() - end);
  return word;
}

bool only_spaces(std::string_view rest) { return rest.find_first_not_of(' ') == std::string_view::npos; }

bool parse_number(std::string_view word, double& value) {
  if (word.empty() || word.size() > 40) {
    return false;
  }
  for (const char c : word) {  // plain decimals only: no "inf", "nan", hex or exponent surprises
    if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+')) {
      return false;
    }
  }
  const char* first = word.data();
  if (*first == '+') {
    ++first;
  }
  const char* last = word.data() + word.size();
  const std::from_chars_result r = std::from_chars(first, last, value);
  return r.ec == std::errc() && r.ptr == last && std::isfinite(value);
}

}  // namespace

SetReply set_reply(std::string_view line, std::string_view name) {
  std::string_view rest = line;
  if (next_word(rest) != "SET" || name.empty() || next_word(rest) != name) {
    return SetReply::Other;
  }
  const std::string_view answer = next_word(rest);
  if (!only_spaces(rest)) {
    return SetReply::Other;
  }
  if (answer == "ACK") {
    return SetReply::Ack;
  }
  return answer == "NAK" ? SetReply::Nak : SetReply::Other;
}

bool hello_accepted(std::string_view line) {
  std::string_view rest = line;
  return next_word(rest) == "HELLO" && next_word(rest) == "ACK";
}

std::string_view value_of(std::string_view line, std::string_view key) {
  std::string_view rest = line;
  if (key.empty() || next_word(rest) != key) {
    return {};
  }
  const std::string_view value = next_word(rest);
  return only_spaces(rest) ? value : std::string_view{};
}

bool parse_xyz(std::string_view line, std::string_view key, std::array<double, 3>& xyz) {
  std::string_view rest = line;
  if (key.empty() || next_word(rest) != key) {
    return false;
  }
  std::array<double, 3> values{};
  for (double& value : values) {
    if (!parse_number(next_word(rest), value)) {
      return false;
    }
  }
  xyz = values;
  return true;
}

bool parse_joints_homed(std::string_view line, std::array<bool, 3>& homed) {
  std::string_view rest = line;
  if (next_word(rest) != "JOINT_HOMED") {
    return false;
  }
  std::array<bool, 3> values{};
  for (bool& value : values) {
    const std::string_view word = next_word(rest);
    if (word != "YES" && word != "NO") {
      return false;
    }
    value = word == "YES";
  }
  homed = values;
  return true;
}

ErrorReply parse_error(std::string_view line, std::string_view& text) {
  std::string_view words = line;
  if (next_word(words) != "ERROR" || words.empty()) {
    return ErrorReply::Other;
  }
  while (!words.empty() && words.front() == ' ') {
    words.remove_prefix(1);
  }
  while (!words.empty() && words.back() == ' ') {
    words.remove_suffix(1);
  }
  if (words.empty()) {
    return ErrorReply::Other;
  }
  if (words == "OK") {
    return ErrorReply::None;
  }
  text = words;
  return ErrorReply::Error;
}

}  // namespace stencil::hal::linuxcnc
