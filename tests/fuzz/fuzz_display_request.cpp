// libFuzzer target: the controller's request decoder (display_link), the only code in a controller's
// process that reads what a display sends, and the rules behind it: never a crash; an error naming
// a byte whenever it says no; a request it takes has a known kind and a finite value, and a Set the
// limits let through is inside them. The input is cut into messages as the socket would deliver them.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "firmware/services/display_link/message_codec.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::display_link;
  for (std::size_t at = 0; at < size; at += kMessageBytes) {
    const std::size_t length = std::min(kMessageBytes, size - at);
    Message message{};
    std::string error;
    const DecodeResult result = decode_request(data + at, length, message, error);
    if (result != DecodeResult::Ok) {
      require(!error.empty());
      if (result == DecodeResult::VersionMismatch) {
        require(error.find("this side speaks version") != std::string::npos);
      }
      break;  // the server closes a stream that is out of step
    }
    require(length == kMessageBytes && message.magic == kMessageMagic && message.version == kProtocolVersion);
    const auto kind = static_cast<MessageKind>(message.kind);
    require(kind == MessageKind::Hello || kind == MessageKind::Set || kind == MessageKind::Reset || kind == MessageKind::Stop ||
            kind == MessageKind::Pause || kind == MessageKind::Resume || kind == MessageKind::Start);
    require(std::isfinite(message.value));
    if (kind == MessageKind::Hello) {
      require(message.parameter == kHelloDisplay || message.parameter == kHelloControl);  // who is speaking
      continue;
    }
    const Request request = request_of(message);
    if (kind == MessageKind::Start) {
      // Never a cycle command: the server hands it to the program waiting for the spindle's start.
      require(request.kind == RequestKind::Start && message.parameter == 0);
      continue;
    }
    const RequestLimits limits;
    const std::string refused = refusal(request, limits);
    const stencil::control::Command command = command_of(request);
    if (request.kind == RequestKind::Set && refused.empty()) {
      require(request.value > 0.0 || (request.value == 0.0 && stencil::control::zero_allowed(command.kind)));
      switch (request.parameter) {
        case Parameter::ForceLimit:
          require(request.value <= limits.board_force_limit_n && command.kind == stencil::control::CommandKind::SetForceLimit);
          break;
        case Parameter::SpeedLimit:
          require(request.value <= limits.mill_speed_mm_per_s && command.kind == stencil::control::CommandKind::SetSpeedLimit);
          break;
        case Parameter::Coupling:
          require(request.value >= limits.min_coupling_n_per_device_mm &&
                  request.value <= limits.max_coupling_n_per_device_mm &&
                  command.kind == stencil::control::CommandKind::SetCoupling);
          break;
        case Parameter::Damping:
          require(request.value <= limits.max_damping_n_s_per_m && command.kind == stencil::control::CommandKind::SetDamping);
          break;
        case Parameter::Friction:
          require(request.value <= 1.0 && command.kind == stencil::control::CommandKind::SetFriction);
          break;
        case Parameter::SpeedLimiting:
          require((request.value == 0.0 || request.value == 1.0) &&
                  command.kind == stencil::control::CommandKind::SetSpeedLimiting);
          break;
      }
    }
    require(command.source == stencil::control::CommandSource::Display);
    if (request.kind == RequestKind::Reset) {
      require(command.kind == stencil::control::CommandKind::Reset);
    }
    // A stop is what it says, always: never another command, never a value.
    require((kind == MessageKind::Stop) == (command.kind == stencil::control::CommandKind::Stop));
    require(kind == MessageKind::Set || command.value == 0.0);
    if (kind == MessageKind::Pause) {
      require(command.kind == stencil::control::CommandKind::Pause);
    }
    if (kind == MessageKind::Resume) {
      require(command.kind == stencil::control::CommandKind::Resume);
    }
  }
  return 0;
}
