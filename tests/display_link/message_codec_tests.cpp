// The request channel's codec: what a controller takes from a display, byte by byte.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "firmware/services/display_link/message_codec.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::display_link;

namespace {

struct Bytes {
  unsigned char data[kMessageBytes];
  explicit Bytes(const Message& message) { std::memcpy(data, &message, kMessageBytes); }
};

std::string decode_error(const Message& message, DecodeResult expected = DecodeResult::Malformed) {
  Bytes bytes(message);
  Message out{};
  std::string error;
  CHECK(expected == decode_request(bytes.data, kMessageBytes, out, error));
  return error;
}

}  // namespace

TEST_GROUP(MessageCodec){};

TEST(MessageCodec, RequestsRoundTrip) {
  const Message set = make_set(Parameter::ForceLimit, 2.5, 42);
  Bytes bytes(set);
  Message out{};
  std::string error;
  CHECK(DecodeResult::Ok == decode_request(bytes.data, kMessageBytes, out, error));
  const Request request = request_of(out);
  CHECK(request.kind == RequestKind::Set);
  CHECK(request.parameter == Parameter::ForceLimit);
  DOUBLES_EQUAL(2.5, request.value, 0.0);
  CHECK_EQUAL(42U, out.id);
  Bytes reset(make_message(MessageKind::Reset, 7));
  CHECK(DecodeResult::Ok == decode_request(reset.data, kMessageBytes, out, error));
  CHECK(request_of(out).kind == RequestKind::Reset);
  const Message refused = make_answer(MessageKind::Refused, 9, "50 N is above the board's force limit");
  Bytes answer(refused);
  CHECK(DecodeResult::Ok == decode_message(answer.data, kMessageBytes, out, error));
  STRCMP_EQUAL("50 N is above the board's force limit", reason_of(out).c_str());
}

TEST(MessageCodec, EveryBadFieldIsNamedByItsByte) {
  Message m = make_set(Parameter::Coupling, 1.0, 1);
  m.magic = 0x12345678;
  STRCMP_CONTAINS("byte 0: not a stencil display message", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, 1.0, 1);
  m.kind = 99;
  STRCMP_CONTAINS("byte 6: unknown kind 99", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, 1.0, 1);
  m.parameter = 6;
  STRCMP_CONTAINS("byte 7: unknown parameter 6 (0 to 5)", decode_error(m).c_str());
  m = make_message(MessageKind::Reset, 1);
  m.parameter = 1;
  STRCMP_CONTAINS("byte 7: expected 0 outside a Set", decode_error(m).c_str());
  m = make_message(MessageKind::Hello, 0);
  m.parameter = kHelloControl;  // a control command's hello: good
  {
    Message out{};
    std::string error;
    Bytes good(m);
    CHECK(DecodeResult::Ok == decode_request(good.data, kMessageBytes, out, error));
  }
  m.parameter = 2;
  STRCMP_CONTAINS("byte 7: who says hello: expected 0 (a display) or 1 (a control command)", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, 1.0, 1);
  m.reserved = 1;
  STRCMP_CONTAINS("byte 12: reserved", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, std::numeric_limits<double>::quiet_NaN(), 1);
  STRCMP_CONTAINS("byte 16: the value is not a finite number", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, 1.0, 1);
  m.reason[5] = 'x';
  STRCMP_CONTAINS("byte 29: expected 0 (no reason here)", decode_error(m).c_str());
  m = make_set(Parameter::Coupling, 1.0, 1);
  std::memset(m.reason, 'x', kReasonBytes);
  STRCMP_CONTAINS("no terminating NUL", decode_error(m).c_str());
  // An answer is not a request.
  STRCMP_CONTAINS("is an answer", decode_error(make_message(MessageKind::Welcome, 1)).c_str());
  // A short read is not a message.
  Message out{};
  std::string error;
  Bytes bytes(make_message(MessageKind::Hello, 1));
  CHECK(DecodeResult::Malformed == decode_request(bytes.data, kMessageBytes - 1, out, error));
  STRCMP_CONTAINS("expected 184", error.c_str());
}

TEST(MessageCodec, AnotherVersionIsAMismatchNamingBoth) {
  Message m = make_message(MessageKind::Hello, 1);
  m.version = static_cast<std::uint16_t>(kProtocolVersion + 1);
  const std::string error = decode_error(m, DecodeResult::VersionMismatch);
  STRCMP_CONTAINS(("protocol version " + std::to_string(kProtocolVersion + 1)).c_str(), error.c_str());
  STRCMP_CONTAINS(("this side speaks version " + std::to_string(kProtocolVersion)).c_str(), error.c_str());
}

TEST(MessageCodec, StopPauseAndResumeAreRequestsWithNoParameterAndNoValue) {
  const MessageKind kinds[] = {MessageKind::Stop, MessageKind::Pause, MessageKind::Resume};
  const RequestKind requests[] = {RequestKind::Stop, RequestKind::Pause, RequestKind::Resume};
  const stencil::control::CommandKind commands[] = {stencil::control::CommandKind::Stop,
                                                    stencil::control::CommandKind::Pause,
                                                    stencil::control::CommandKind::Resume};
  for (int i = 0; i < 3; ++i) {
    Bytes bytes(make_message(kinds[i], 3));
    Message out{};
    std::string error;
    CHECK(DecodeResult::Ok == decode_request(bytes.data, kMessageBytes, out, error));
    const Request request = request_of(out);
    CHECK(request.kind == requests[i]);
    const stencil::control::Command command = command_of(request);
    CHECK(command.kind == commands[i]);
    CHECK(command.source == stencil::control::CommandSource::Display);
    Message bad = make_message(kinds[i], 3);
    bad.value = 1.0;
    STRCMP_CONTAINS("byte 16: expected 0 outside a Set", decode_error(bad).c_str());
  }
}
