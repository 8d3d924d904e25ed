#include "firmware/services/display_link/message_codec.hpp"

#include <cmath>
#include <cstring>

namespace stencil::display_link {
namespace {

bool known_kind(std::uint8_t kind) {
  switch (static_cast<MessageKind>(kind)) {
    case MessageKind::Hello:
    case MessageKind::Set:
    case MessageKind::Reset:
    case MessageKind::Stop:
    case MessageKind::Pause:
    case MessageKind::Resume:
    case MessageKind::Start:
    case MessageKind::Welcome:
    case MessageKind::Accepted:
    case MessageKind::Refused:
    case MessageKind::Mismatch:
      return true;
  }
  return false;
}

std::string at(std::size_t offset, const std::string& what) { return "byte " + std::to_string(offset) + ": " + what; }

}  // namespace

DecodeResult decode_message(const unsigned char* bytes, std::size_t size, Message& message, std::string& error) {
  if (bytes == nullptr || size != kMessageBytes) {
    error = "a message of " + std::to_string(size) + " bytes: expected " + std::to_string(kMessageBytes);
    return DecodeResult::Malformed;
  }
  std::memcpy(&message, bytes, kMessageBytes);
  if (message.magic != kMessageMagic) {
    error = at(offsetof(Message, magic), "not a stencil display message (bad magic)");
    return DecodeResult::Malformed;
  }
  if (message.version != kProtocolVersion) {
    error = "protocol version " + std::to_string(message.version) + " from the other side, this side speaks version " +
            std::to_string(kProtocolVersion);
    return DecodeResult::VersionMismatch;
  }
  if (!known_kind(message.kind)) {
    error = at(offsetof(Message, kind), "unknown kind " + std::to_string(message.kind));
    return DecodeResult::Malformed;
  }
  const auto kind = static_cast<MessageKind>(message.kind);
  const std::uint8_t most = kind == MessageKind::Set     ? kParameterCount - 1
                            : kind == MessageKind::Hello ? kHelloControl
                                                         : 0;
  if (message.parameter > most) {
    error = at(offsetof(Message, parameter), kind == MessageKind::Set     ? "unknown parameter " + std::to_string(message.parameter) + " (0 to " + std::to_string(kParameterCount - 1) + ")"
                                             : kind == MessageKind::Hello ? "who says hello: expected 0 (a display) or 1 (a control command)"
                                                                          : "expected 0 outside a Set and a Hello");
    return DecodeResult::Malformed;
  }
  if (message.reserved != 0) {
    error = at(offsetof(Message, reserved), "reserved, expected 0");
    return DecodeResult::Malformed;
  }
  if (!std::isfinite(message.value) || (kind != MessageKind::Set && message.value != 0.0)) {
    error = at(offsetof(Message, value), kind == MessageKind::Set ? "the value is not a finite number" : "expected 0 outside a Set");
    return DecodeResult::Malformed;
  }
  const bool has_reason = kind == MessageKind::Refused || kind == MessageKind::Mismatch;
  const void* end = std::memchr(message.reason, '\0', kReasonBytes);
  if (end == nullptr) {
    error = at(offsetof(Message, reason), "the reason has no terminating NUL");
    return DecodeResult::Malformed;
  }
  const auto length = static_cast<std::size_t>(static_cast<const char*>(end) - message.reason);
  for (std::size_t i = has_reason ? length : 0; i < kReasonBytes; ++i) {
    if (message.reason[i] != '\0') {
      error = at(offsetof(Message, reason) + i, has_reason ? "expected 0 after the reason's end" : "expected 0 (no reason here)");
      return DecodeResult::Malformed;
    }
  }
  return DecodeResult::Ok;
}

DecodeResult decode_request(const unsigned char* bytes, std::size_t size, Message& message, std::string& error) {
  const DecodeResult result = decode_message(bytes, size, message, error);
  if (result != DecodeResult::Ok) {
    return result;
  }
  const auto kind = static_cast<MessageKind>(message.kind);
  if (static_cast<std::uint8_t>(kind) >= static_cast<std::uint8_t>(MessageKind::Welcome)) {
    error = at(offsetof(Message, kind),
               "kind " + std::to_string(message.kind) + " is an answer: a display sends Hello, Set, Reset, Stop, Pause, Resume or Start");
    return DecodeResult::Malformed;
  }
  return DecodeResult::Ok;
}

Message make_message(MessageKind kind, std::uint32_t id) {
  Message message{};
  message.magic = kMessageMagic;
  message.version = kProtocolVersion;
  message.kind = static_cast<std::uint8_t>(kind);
  message.id = id;
  return message;
}

Message make_set(Parameter parameter, double value, std::uint32_t id) {
  Message message = make_message(MessageKind::Set, id);
  message.parameter = static_cast<std::uint8_t>(parameter);
  message.value = value;
  return message;
}

Message make_answer(MessageKind kind, std::uint32_t id, const std::string& reason) {
  Message message = make_message(kind, id);
  std::memcpy(message.reason, reason.data(), std::min(reason.size(), kReasonBytes - 1));
  return message;
}

Request request_of(const Message& message) {
  switch (static_cast<MessageKind>(message.kind)) {
    case MessageKind::Set:
      return Request{RequestKind::Set, static_cast<Parameter>(message.parameter), message.value};
    case MessageKind::Stop:
      return Request{RequestKind::Stop, Parameter::Coupling, 0.0};
    case MessageKind::Pause:
      return Request{RequestKind::Pause, Parameter::Coupling, 0.0};
    case MessageKind::Resume:
      return Request{RequestKind::Resume, Parameter::Coupling, 0.0};
    case MessageKind::Start:
      return Request{RequestKind::Start, Parameter::Coupling, 0.0};
    default:
      return Request{RequestKind::Reset, Parameter::Coupling, 0.0};
  }
}

std::string reason_of(const Message& message) {
  const void* end = std::memchr(message.reason, '\0', kReasonBytes);
  return std::string(message.reason, end != nullptr ? static_cast<std::size_t>(static_cast<const char*>(end) - message.reason)
                                                    : kReasonBytes);
}

}  // namespace stencil::display_link
