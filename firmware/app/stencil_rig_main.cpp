// stencil-rig: the controller on the real rig (board sherline_suzuki): the haptic device over the
// PIO shared-memory card or SocketCAN, the mill's CY545 over RS-232. It starts by checking
// everything it can (the host's real-time readiness, the tables, the serial port, the haptic link)
// and says plainly what is missing.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "firmware/app/rt_readiness.hpp"
#include "firmware/tables/table_loader.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/socketcan/can_frame_layout.hpp"
#include "hal/socketcan/fd_can_channel.hpp"

namespace {

using namespace stencil;

constexpr int kExitBadInput = 2;
constexpr int kExitNotStarted = 3;

int fail(int status, const std::string& message) {
  std::fprintf(stderr, "stencil-rig: %s\n", message.c_str());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "stencil-rig: the haptic stencil controller on the Sherline + Suzuki rig. Checks the host's real-time\n"
      "readiness, loads the tables, opens the CY545's serial port and the haptic device's link, and says what\n"
      "is missing. The real-time run loop on the rig is not built yet: with everything present it says so and\n"
      "stops (use stencil-sim for the simulated rig). Exit status: 2 bad input, 3 could not start."};
  std::string tables_path;
  std::string serial_path;
  std::string haptic;
  bool require_rt = false;
  int priority = 80;
  app.add_option("--tables", tables_path, "the part's .stbl")->required();
  app.add_option("--serial", serial_path, "the CY545's serial port, e.g. /dev/ttyS0")->required();
  app.add_option("--haptic", haptic, "the haptic link: pio:/dev/uioN or can:IFACE")->required();
  app.add_flag("--require-rt", require_rt, "refuse to run without PREEMPT_RT and SCHED_FIFO");
  app.add_option("--priority", priority, "the cycle thread's SCHED_FIFO priority")->check(CLI::Range(1, 99))->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), kExitBadInput);
  }
  const bool pio = haptic.rfind("pio:", 0) == 0;
  const bool can = haptic.rfind("can:", 0) == 0;
  if ((!pio && !can) || haptic.size() <= 4) {
    return fail(kExitBadInput, "--haptic " + haptic + ": expected pio:/dev/uioN or can:IFACE");
  }

  std::vector<unsigned char> bytes;
  {
    std::ifstream in(tables_path, std::ios::binary);
    if (!in) {
      return fail(kExitBadInput, tables_path + ": cannot be read");
    }
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  tables::PartTables part{};
  const tables::TableLoadResult loaded = tables::load_tables({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, part);
  if (!loaded.ok) {
    return fail(kExitBadInput, tables_path + ": not a valid table: " + loaded.field);
  }
  std::printf("stencil-rig: tables %s: %u points, %u triangles\n", tables_path.c_str(), part.point_count(),
              part.triangle_count());

  const app::RtReadiness readiness = app::check_rt_readiness(bytes.size() + (64U << 20), priority);
  std::printf("real-time readiness:\n%s", app::describe(readiness).c_str());
  if (require_rt && (!readiness.preempt_rt || !readiness.can_sched_fifo)) {
    return fail(kExitNotStarted, "--require-rt: this host has no PREEMPT_RT kernel or may not use SCHED_FIFO");
  }

  hal::cy545::SerialPort port;
  char port_error[256] = {};
  if (!port.open(serial_path.c_str(), port_error)) {
    return fail(kExitNotStarted, std::string("the mill's CY545: ") + port_error);
  }
  std::string error;
  if (pio) {
    const std::string path = haptic.substr(4);
    const auto window = hal::pio_shared_memory::SharedWindowMapping::open(path, 0, true, error);
    if (window == nullptr) {
      return fail(kExitNotStarted, "the haptic device's PIO window: " + error);
    }
  } else {
    const std::string interface = haptic.substr(4);
    const canid_t ids[] = {hal::socketcan::kPoseAId, hal::socketcan::kPoseBId, hal::socketcan::kStatusId};
    const int fd = hal::socketcan::open_can_raw_socket(interface, ids, 3, error);
    if (fd < 0) {
      return fail(kExitNotStarted, "the haptic device's CAN link: " + error);
    }
    hal::socketcan::FdCanChannel channel(fd);
  }
  return fail(kExitNotStarted,
              "every link opened, but the rig's real-time run loop is not built yet; nothing was moved");
}
