// libFuzzer target: the CAN frame decoders on both sides take any sequence of frames, refuse what
// is bad, and never hand out a pose or command beyond the ranges.
#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/haptic_device.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::hal;
  using namespace stencil::hal::socketcan;
  HostFrameAssembler host(stencil::board::sherline_suzuki::kCentredDeviceRange);
  DeviceFrameAssembler device;
  for (std::size_t offset = 0; offset + sizeof(can_frame) <= size; offset += sizeof(can_frame)) {
    can_frame frame{};
    std::memcpy(&frame, data + offset, sizeof frame);
    const FrameResult from_device = host.accept(frame);
    if (from_device.effect == FrameEffect::Completed) {
      const PoseWire& pose = host.latest_pose();
      for (int axis = 0; axis < 3; ++axis) {
        require(std::abs(pose.position_um[axis] * 1e-3 - stencil::board::sherline_suzuki::kCentredDeviceRange.position_centre_mm[axis]) <=
                stencil::board::sherline_suzuki::kCentredDeviceRange.position_limit_mm[axis]);
      }
    }
    const FrameResult from_host = device.accept(frame);
    if (from_host.effect == FrameEffect::Completed) {
      const CommandWire& command = device.latest_command();
      for (int axis = 0; axis < 3; ++axis) {
        require(std::abs(command.force_mn[axis]) <= static_cast<int>(stencil::board::sherline_suzuki::kCentredDeviceRange.force_limit_n * 1000.0));
      }
    }
  }
  return 0;
}
