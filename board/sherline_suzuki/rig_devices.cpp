#include "board/sherline_suzuki/rig_devices.hpp"

#include "board/sherline_suzuki/rig_facts.hpp"

#include "hal/socketcan/can_frame_layout.hpp"
#include "hal/socketcan/can_interface_bitrate.hpp"

namespace stencil::board::sherline_suzuki {
namespace {

bool open_pio(const hal::HapticRange& range, const std::string& path, RigDevices& devices, std::string& error) {
  devices.window = hal::pio_shared_memory::SharedWindowMapping::open(path, 0, true, error);
  if (devices.window == nullptr) {
    error = "the haptic device's PIO window: " + error;
    return false;
  }
  devices.pio_device =
      std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&devices.window->window(), range);
  devices.device = devices.pio_device.get();
  return true;
}

bool open_can(const hal::HapticRange& range, const std::string& interface, RigDevices& devices, const std::function<void(const std::string&)>& note,
              std::string& error) {
  const canid_t ids[] = {hal::socketcan::kPoseAId, hal::socketcan::kPoseBId, hal::socketcan::kStatusId};
  const int fd = hal::socketcan::open_can_raw_socket(interface, ids, 3, error);
  if (fd < 0) {
    error = "the haptic device's CAN link: " + error;
    return false;
  }
  devices.channel = std::make_unique<hal::socketcan::FdCanChannel>(fd);
  // A bus too slow for a period's frames is refused here, not found out as late poses in the cycle.
  std::string bitrate_note;
  if (!hal::socketcan::check_can_bitrate(interface, bitrate_note, error)) {
    error = "the haptic device's CAN link: " + error;
    return false;
  }
  note(bitrate_note);
  devices.can_device =
      std::make_unique<hal::socketcan::SocketCanHapticDevice>(devices.channel.get(), range);
  devices.device = devices.can_device.get();
  return true;
}

}  // namespace

bool is_haptic_link_name(const std::string& haptic) {
  return (haptic.rfind("pio:", 0) == 0 || haptic.rfind("can:", 0) == 0) && haptic.size() > 4;
}

bool open_rig_devices(const RigFacts& facts, const std::string& serial_path, const std::string& haptic,
                      RigDevices& devices, const std::function<void(const std::string&)>& note, std::string& error) {
  char port_error[256] = {};
  const bool linuxcnc = facts.controller == MachineController::Linuxcnc;
  if (!linuxcnc && !devices.port.open(serial_path.c_str(), facts.serial_baud, port_error)) {
    error = std::string("the mill's CY545: ") + port_error;
    return false;
  }
  const hal::HapticRange range = programs_device_range(facts);
  const bool opened = haptic.rfind("pio:", 0) == 0 ? open_pio(range, haptic.substr(4), devices, error)
                                                   : open_can(range, haptic.substr(4), devices, note, error);
  if (!opened) {
    return false;
  }
  if (linuxcnc) {
    devices.linuxcnc = std::make_unique<hal::linuxcnc::LinuxcncLink>(devices.clock, linuxcnc_config(facts));
    return true;
  }
  devices.link = std::make_unique<hal::cy545::Cy545Link>(devices.port, devices.clock, cy545_config(facts));
  return true;
}

bool open_rig_machine(const RigFacts& facts, const std::string& serial_path, RigDevices& devices, std::string& error) {
  if (facts.controller == MachineController::Linuxcnc) {
    error = "commissioning measures the CY545 rig's axes against a dial indicator; a LinuxCNC mill's steps per mm and "
            "backlash are set and checked in its own INI (machine.controller is \"linuxcnc\")";
    return false;
  }
  char port_error[256] = {};
  if (!devices.port.open(serial_path.c_str(), facts.serial_baud, port_error)) {
    error = std::string("the mill's CY545: ") + port_error;
    return false;
  }
  devices.link = std::make_unique<hal::cy545::Cy545Link>(devices.port, devices.clock, cy545_config(facts));
  return true;
}

}  // namespace stencil::board::sherline_suzuki
