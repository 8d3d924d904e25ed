// libFuzzer target: the CY545 query reply parser reads only its input and keeps its promises.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/cy545/cy545_commands.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) {
    return 0;
  }
  using namespace stencil::hal::cy545;
  // First byte: the queried letter; the rest: what came back on the line.
  const char letter = static_cast<char>(data[0]);
  const std::string_view reply(reinterpret_cast<const char*>(data + 1), size - 1);
  const ReplyParse parsed = parse_reply(reply, letter);
  switch (parsed.status) {
    case ReplyStatus::Complete:
      require(parsed.length >= 4 && parsed.length <= reply.size());
      require(reply[parsed.length - 1] == '\r' && reply[0] == letter && reply[1] == '=');
      require(parsed.value <= kMax24);
      break;
    case ReplyStatus::Garbled:
      require((parsed.at < reply.size() || parsed.at == 0) && parsed.expected != nullptr && parsed.expected[0] != '\0');
      break;
    case ReplyStatus::Incomplete:
      require(reply.find('\r') == std::string_view::npos || reply.size() < 2);
      break;
  }
  return 0;
}
