// The request channel's Messages to and from bytes. Decoding is the controller's only parser of what
// a display sends: every byte is checked (magic, version, kind, parameter, a finite value, reserved
// bytes zero, the reason's terminator), and what is wrong is named by its offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "firmware/services/display_link/display_wire.hpp"

namespace stencil::display_link {

enum class DecodeResult : std::uint8_t { Ok, Malformed, VersionMismatch };

// `bytes` must be exactly kMessageBytes. VersionMismatch: a Hello (or any message) of another
// version; `error` names both. Malformed: `error` names the byte and what was expected.
[[nodiscard]] DecodeResult decode_message(const unsigned char* bytes, std::size_t size, Message& message, std::string& error);

// Only what a controller takes from a display (Hello, Set, Reset); the answers are refused.
[[nodiscard]] DecodeResult decode_request(const unsigned char* bytes, std::size_t size, Message& message,
                                          std::string& error);

[[nodiscard]] Message make_message(MessageKind kind, std::uint32_t id);
[[nodiscard]] Message make_set(Parameter parameter, double value, std::uint32_t id);
[[nodiscard]] Message make_answer(MessageKind kind, std::uint32_t id, const std::string& reason);
[[nodiscard]] Request request_of(const Message& message);  // Set or Reset
[[nodiscard]] std::string reason_of(const Message& message);

}  // namespace stencil::display_link
