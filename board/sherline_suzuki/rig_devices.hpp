// The rig's devices, opened from the command line's names: the haptic device over the PIO card's
// shared-memory window (pio:/dev/uioN) or SocketCAN (can:IFACE), and the mill: the CY545 on its
// serial port, or LinuxCNC over linuxcncrsh (machine.controller = "linuxcnc").
// Each failure names the link and what was wrong, before anything moves.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/haptic_device.hpp"
#include "hal/linuxcnc/linuxcnc_link.hpp"
#include "hal/machine_link.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"

namespace stencil::board::sherline_suzuki {

// Owns what it opened; `device` and `machine()` point into it once open_rig_devices succeeded.
struct RigDevices {
  hal::cy545::SerialPort port;
  hal::posix_clock::MonotonicClock clock;  // the link's, and the machine thread's pacing
  std::unique_ptr<hal::cy545::Cy545Link> link;               // the CY545's, or
  std::unique_ptr<hal::linuxcnc::LinuxcncLink> linuxcnc;     // LinuxCNC's
  [[nodiscard]] hal::MachineLink& machine() {
    return link ? static_cast<hal::MachineLink&>(*link) : static_cast<hal::MachineLink&>(*linuxcnc);
  }
  // The mill's link's last error (the CY545's bytes, LinuxCNC's words).
  [[nodiscard]] const char* machine_error() const {
    return link ? link->last_error() : (linuxcnc ? linuxcnc->last_error() : "");
  }
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> window;
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> pio_device;
  std::unique_ptr<hal::socketcan::FdCanChannel> channel;
  std::unique_ptr<hal::socketcan::SocketCanHapticDevice> can_device;
  hal::HapticDevice* device = nullptr;
};

// True when `haptic` names a link this board knows: "pio:PATH" or "can:IFACE".
[[nodiscard]] bool is_haptic_link_name(const std::string& haptic);

// Opens the serial port and the haptic link of the rig `facts` describe (its baud, the device's range,
// the CY545's configuration); `note` gets a line worth telling (the CAN bus's bitrate). False with
// `error` naming the link.
[[nodiscard]] bool open_rig_devices(const RigFacts& facts, const std::string& serial_path, const std::string& haptic,
                                    RigDevices& devices,
                                    const std::function<void(const std::string&)>& note, std::string& error);

// The serial port and the CY545 link only (commissioning needs no haptic device; a LinuxCNC mill is
// commissioned in its own INI, and is refused here).
[[nodiscard]] bool open_rig_machine(const RigFacts& facts, const std::string& serial_path, RigDevices& devices,
                                    std::string& error);

}  // namespace stencil::board::sherline_suzuki
