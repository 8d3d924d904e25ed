// Opening the rig's devices by name (board/sherline_suzuki/rig_devices): which haptic link names the
// board knows, and each failure naming the link it was on, before anything moves. The serial port is
// a pty here; the PIO window and the CAN interface do not exist, so their refusals are what is seen.
#include <cstdlib>
#include <functional>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "board/sherline_suzuki/rig_devices.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

namespace {

// A pty whose slave stands in for the CY545's serial port.
struct Pty {
  int master = -1;
  std::string slave;
  Pty() {
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master >= 0 && grantpt(master) == 0 && unlockpt(master) == 0) {
      slave = ptsname(master);
    }
  }
  ~Pty() {
    if (master >= 0) {
      close(master);
    }
  }
};

const std::function<void(const std::string&)> kIgnore = [](const std::string&) {};

}  // namespace

TEST_GROUP(RigDevices){};

TEST(RigDevices, KnowsPioAndCanLinksWithANameAfterThePrefix) {
  CHECK_TRUE(is_haptic_link_name("pio:/dev/uio0"));
  CHECK_TRUE(is_haptic_link_name("can:can0"));
  CHECK_FALSE(is_haptic_link_name("pio:"));
  CHECK_FALSE(is_haptic_link_name("can:"));
  CHECK_FALSE(is_haptic_link_name("usb:/dev/ttyUSB0"));
  CHECK_FALSE(is_haptic_link_name("/dev/uio0"));
  CHECK_FALSE(is_haptic_link_name(""));
}

TEST(RigDevices, AMissingSerialPortIsTheMillsCy545) {
  RigDevices devices;
  std::string error;
  CHECK_FALSE(open_rig_machine(kRig, "/nonexistent/ttyS9", devices, error));
  STRCMP_CONTAINS("the mill's CY545: ", error.c_str());
  CHECK(devices.link == nullptr);
  RigDevices both;
  CHECK_FALSE(open_rig_devices(kRig, "/nonexistent/ttyS9", "pio:/dev/uio0", both, kIgnore, error));
  STRCMP_CONTAINS("the mill's CY545: ", error.c_str());
  CHECK(both.device == nullptr);
}

TEST(RigDevices, TheMachineAloneOpensOnAPort) {
  const Pty pty;
  CHECK_FALSE(pty.slave.empty());
  RigDevices devices;
  std::string error;
  CHECK_TRUE(open_rig_machine(kRig, pty.slave, devices, error));
  CHECK(devices.link != nullptr);
  CHECK(devices.device == nullptr);
}

TEST(RigDevices, AMissingPioWindowIsTheHapticDevicesAndLeavesNoLink) {
  const Pty pty;
  RigDevices devices;
  std::string error;
  CHECK_FALSE(open_rig_devices(kRig, pty.slave, "pio:/nonexistent/uio9", devices, kIgnore, error));
  STRCMP_CONTAINS("the haptic device's PIO window: ", error.c_str());
  CHECK(devices.device == nullptr);
  CHECK(devices.link == nullptr);
}

TEST(RigDevices, AMissingCanInterfaceIsTheHapticDevicesCanLink) {
  const Pty pty;
  RigDevices devices;
  std::string error;
  CHECK_FALSE(open_rig_devices(kRig, pty.slave, "can:nosuchcan9", devices, kIgnore, error));
  STRCMP_CONTAINS("the haptic device's CAN link: ", error.c_str());
  CHECK(devices.device == nullptr);
}

// A LinuxCNC mill (machine.controller = "linuxcnc"): no serial port is opened, the link is LinuxCNC's
// (nothing connects until it starts), and commissioning, which measures the CY545 rig's axes, refuses.
TEST(RigDevices, ALinuxcncMillOpensNoSerialPortAndIsNotCommissionedHere) {
  RigFacts facts = kRig;
  facts.controller = MachineController::Linuxcnc;
  facts.linuxcnc.connect_password = {'h', 'e', 'l', 'l', 'o'};
  facts.linuxcnc.enable_password = {'e', 'n', 'a', 'b', 'l', 'e'};
  RigDevices devices;
  std::string error;
  // The PIO window is missing, so the haptic link fails; the serial port was never looked at.
  CHECK_FALSE(open_rig_devices(facts, "/nonexistent/ttyS9", "pio:/nonexistent/uio9", devices, kIgnore, error));
  STRCMP_CONTAINS("haptic", error.c_str());
  CHECK(devices.link == nullptr);
  RigDevices alone;
  CHECK_FALSE(open_rig_machine(facts, "/nonexistent/ttyS9", alone, error));
  STRCMP_CONTAINS("LinuxCNC mill", error.c_str());
  CHECK(alone.link == nullptr);
  CHECK(alone.linuxcnc == nullptr);
}
