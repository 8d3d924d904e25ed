// The simulation board's wiring and its fast run loop.
//
// On virtual time the cycle and the machine side take turns on one thread: the cycle runs period
// after period until its time reaches the machine's; then the machine side runs one update, whose
// link waits move the machine's clock (FakeCy545Clock), and with it the fake CY545 and the mill,
// by as long as the serial line and the moves take. The machine only ever sees the handoffs of
// cycles before its update, as on the rig, and nothing depends on the wall clock.
#include "board/sim/sim_job.hpp"

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <thread>

#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include "board/sim/device_process.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/machine_side.hpp"
#include "firmware/services/journal/journal_drain.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/direct_haptic_device.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/replay_haptic_device.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "sim/mill/machined_part.hpp"
#include "sim/mill/simulated_mill.hpp"

namespace stencil::board::sim {
namespace {

// kPeriodNs, kUpdateNs, kWatchdogRelayNs, kBaud, kModelCellMm: sim_facts.hpp (the rig's).
// An update's bound from its actual start: a move of one period's steps plus the CY545's commands,
// each with its settle (up to about 40 ms for three axes that change channel), fits in three periods;
// an update that takes longer than a period only makes the mill fall behind (the backlog slows the
// virtual tool), never a fault.
constexpr hal::MonotonicNs kUpdateBoundNs = 3 * kUpdateNs;


Quantiles quantiles_of(const control::MicrosecondHistogram& histogram) {
  return {histogram.quantile_us(0.5), histogram.quantile_us(0.99), histogram.quantile_us(0.999),
          static_cast<double>(histogram.max_ns()) / 1000.0};
}

double reachable_coverage(const tables::PartTables& part, const engine::TriangleSet& touched) {
  if (part.header.reachable_triangle_count == 0) {
    return 1.0;
  }
  std::uint32_t covered = 0;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    covered += (part.triangle_flags[t] & tables::kTriangleReachable) != 0 && touched.contains(t) ? 1U : 0U;
  }
  return static_cast<double>(covered) / static_cast<double>(part.header.reachable_triangle_count);
}

// The simulated device as the cycle sees it, by the chosen transport. The hand's handle is where the
// device's samples say; `rendered()` is what the device's motors drive now.
class SimulatedDeviceWiring {
 public:
  SimulatedDeviceWiring(HapticTransport transport, const stencil::sim::OperatorHand& hand, std::string& error)
      : transport_(transport), direct_(kDeviceRange) {
    const auto pose = [&hand, this](std::uint32_t, hal::MonotonicNs) {
      const Eigen::Vector3d at = disturbed(hand.handle_mm);
      return stencil::sim::SimulatedPose{{at.x(), at.y(), at.z()}, {0.0, 0.0}};
    };
    if (transport == HapticTransport::Pio) {
      window_ = hal::pio_shared_memory::SharedWindowMapping::create_memfd("stencil-sim-pio", error);
      if (window_ == nullptr) {
        return;
      }
      device_link_ = std::make_unique<stencil::sim::PioDeviceLink>(window_->window());
      pio_host_ = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&window_->window(), kDeviceRange);
      host_ = pio_host_.get();
    } else if (transport == HapticTransport::Can) {
      int fds[2] = {-1, -1};
      if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0, fds) != 0) {
        error = "socketpair for the simulated CAN bus failed";
        return;
      }
      host_channel_ = std::make_unique<hal::socketcan::FdCanChannel>(fds[0]);
      device_channel_ = std::make_unique<hal::socketcan::FdCanChannel>(fds[1]);
      auto can_link = std::make_unique<stencil::sim::CanDeviceLink>(*device_channel_);
      can_device_link_ = can_link.get();
      device_link_ = std::move(can_link);
      can_host_ = std::make_unique<hal::socketcan::SocketCanHapticDevice>(host_channel_.get(), kDeviceRange);
      host_ = can_host_.get();
    }
    if (device_link_ != nullptr) {
      simulated_ = std::make_unique<stencil::sim::SimulatedHapticDevice>(*device_link_, pose);
    }
  }

  [[nodiscard]] bool ready() const { return transport_ == HapticTransport::Direct || simulated_ != nullptr; }
  [[nodiscard]] stencil::sim::SimulatedHapticDevice* simulated() { return simulated_.get(); }
  [[nodiscard]] hal::HapticDevice& host() { return transport_ == HapticTransport::Direct ? direct_ : *host_; }

  // The device's millisecond: a new sample of the handle, the host's newest command taken.
  void device_cycle(const stencil::sim::OperatorHand& hand, const Eigen::Vector2d& angles, hal::MonotonicNs now_ns) {
    if (transport_ == HapticTransport::Direct) {
      if (frozen_) {
        return;
      }
      ++counter_;
      const Eigen::Vector3d at = disturbed(hand.handle_mm);
      direct_.publish({{at.x(), at.y(), at.z()}, {angles.x(), angles.y()}, counter_,
                       hal::haptic_status::kForceApplied | (device_fault_ ? hal::haptic_status::kDeviceFault : 0U), counter_});
    } else {
      simulated_->step(now_ns);
    }
    jump_ = false;  // a jump is one sample
  }

  // The device's side of an injected fault.
  void inject(FaultKind kind) {
    switch (kind) {
      case FaultKind::DeviceFrozen:
        frozen_ = true;
        if (simulated_ != nullptr) {
          simulated_->set_frozen(true);
        }
        break;
      case FaultKind::PoseNan:
        nan_ = true;
        break;
      case FaultKind::PoseJump:
        jump_ = true;
        break;
      case FaultKind::CanBadFrames:
        if (can_device_link_ != nullptr) {
          can_device_link_->babble(20);
        }
        break;
      case FaultKind::DeviceFault:
        device_fault_ = true;
        if (simulated_ != nullptr) {
          simulated_->set_device_fault(true);
        }
        break;
      default:
        break;
    }
  }

  // Zero force at the device: the command it drives (direct) or its own output (over a wire).
  [[nodiscard]] bool force_off() const {
    if (transport_ == HapticTransport::Direct) {
      return !direct_.rendered().enable || rendered_force().norm() == 0.0;
    }
    return !simulated_->output().force_applied || rendered_force().norm() == 0.0;
  }

  [[nodiscard]] Eigen::Vector3d rendered_force() const {
    if (transport_ == HapticTransport::Direct) {
      const hal::HapticCommand& c = direct_.rendered();
      return {c.force_n[0], c.force_n[1], c.force_n[2]};
    }
    const stencil::sim::DeviceOutput output = simulated_->output();
    return {output.force_n[0], output.force_n[1], output.force_n[2]};
  }

 private:
  HapticTransport transport_;
  stencil::sim::DirectHapticDevice direct_;
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> window_;
  std::unique_ptr<hal::socketcan::FdCanChannel> host_channel_, device_channel_;
  std::unique_ptr<stencil::sim::DeviceSideLink> device_link_;
  stencil::sim::CanDeviceLink* can_device_link_ = nullptr;  // device_link_, over CAN
  // The backends' destructors are theirs (HapticDevice's is protected): one owner each.
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> pio_host_;
  std::unique_ptr<hal::socketcan::SocketCanHapticDevice> can_host_;
  hal::HapticDevice* host_ = nullptr;
  bool frozen_ = false, nan_ = false, jump_ = false, device_fault_ = false;

  [[nodiscard]] Eigen::Vector3d disturbed(const Eigen::Vector3d& handle) const {
    if (nan_) {
      return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    return jump_ ? Eigen::Vector3d(handle + Eigen::Vector3d(100.0, 0.0, 0.0)) : handle;
  }
  std::unique_ptr<stencil::sim::SimulatedHapticDevice> simulated_;
  std::uint32_t counter_ = 0;
};

}  // namespace

motion::MachineFrames frames() {
  // Every axis counts into the workspace from its switch, so the world runs against all three.
  return {kDeviceMmPerWorldMm, Eigen::Vector3d::Zero(),
          Eigen::Vector3d(kHomeWorldMm[0], kHomeWorldMm[1], kHomeWorldMm[2]), rig::kRig.machine_sign, rig::kRig.steps_per_mm};
}

stencil::sim::StockBox default_stock(const tables::PartTables& part) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300), high = Eigen::Vector3d::Constant(-1e300);
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    for (const tables::PackedPoint& v : part.triangles[t].vertices) {
      const Eigen::Vector3d p(v.x_mm, v.y_mm, v.z_mm);
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  const Eigen::Vector3d workspace(part.header.workspace_mm[0], part.header.workspace_mm[1], part.header.workspace_mm[2]);
  const Eigen::Vector3d margin(2.0, 2.0, 0.0);
  return {(low - margin).cwiseMax(Eigen::Vector3d::Zero()).cwiseProduct(Eigen::Vector3d(1, 1, 0)),
          (high + margin + Eigen::Vector3d(0, 0, 1.0)).cwiseMin(workspace)};
}

control::ControllerConfig controller_config(bool realtime) {
  const motion::MachineFrames frames = sim::frames();
  control::ControllerConfig config;
  config.frames = frames;
  config.contact.device_mm_per_world_mm = kDeviceMmPerWorldMm;
  config.haptic.device_mm_per_world_mm = kDeviceMmPerWorldMm;
  config.haptic.max_force_n = rig::kRig.force_limit_n;
  config.haptic.max_torque_nmm = rig::kRig.torque_limit_nmm;
  config.period_s = 1.0 / rig::kRig.haptic_rate_hz;
  config.device_low_mm = Eigen::Vector3d::Constant(-rig::kRig.device_reach_margin_mm);
  config.device_high_mm = Eigen::Vector3d(rig::kRig.haptic_workspace_mm[0] + rig::kRig.device_reach_margin_mm,
                                          rig::kRig.haptic_workspace_mm[1] + rig::kRig.device_reach_margin_mm,
                                          rig::kRig.haptic_workspace_mm[2] + rig::kRig.device_reach_margin_mm);
  config.home_tip_mm = frames.home_world_mm;
  config.count_overruns = realtime;  // on virtual time lateness means nothing
  config.max_axis_move_mm = kVirtualToolSpeedMmPerS * config.period_s;
  config.max_total_move_mm = kVirtualToolSpeedMmPerS * config.period_s;
  return config;
}

std::function<double(double, double)> touch_tip_of(const tables::PartTables& part, const stencil::sim::StockBox& stock) {
  auto grid = std::make_shared<stencil::sim::StockZmap>(stock, 0.05);
  auto tips = std::make_shared<std::vector<double>>(
      stencil::sim::lowest_tips(*grid, stencil::sim::part_top_heights(part, *grid), stencil::sim::ToolProfile::of(part.tool.spec)));
  return [grid, tips](double x, double y) {
    const int column = std::clamp(static_cast<int>((x - grid->box().low_mm.x()) / grid->cell_mm()), 0, grid->columns() - 1);
    const int row = std::clamp(static_cast<int>((y - grid->box().low_mm.y()) / grid->cell_mm()), 0, grid->rows() - 1);
    return (*tips)[static_cast<std::size_t>(row) * static_cast<std::size_t>(grid->columns()) + static_cast<std::size_t>(column)];
  };
}

namespace {

// An injected fault where it happens: the device's side, or the far end of the serial line.
void inject(FaultKind kind, SimulatedDeviceWiring& device, stencil::sim::cy545::FakeCy545& fake) {
  switch (kind) {
    case FaultKind::Cy545Silent:
      fake.set_replies_suppressed(true);
      break;
    case FaultKind::Cy545Garbled:
      fake.set_replies_garbled(true);
      break;
    case FaultKind::SerialGarbage:
      fake.send_unsolicited("\x13Z#?\x7f 9\r\x05");
      break;
    case FaultKind::SerialClosed:
      fake.close_pty();
      break;
    case FaultKind::PositionMismatch:
      fake.set_reported_position_offset(100);
      break;
    default:
      device.inject(kind);
      break;
  }
}

// This process's resident memory now, and the most it has been (getrusage), kB.
std::int64_t resident_kb() {
  long pages = 0, resident = 0;
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (statm != nullptr) {
    if (std::fscanf(statm, "%ld %ld", &pages, &resident) != 2) {
      resident = 0;
    }
    std::fclose(statm);
  }
  return static_cast<std::int64_t>(resident) * (sysconf(_SC_PAGESIZE) / 1024);
}

std::int64_t max_resident_kb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// The result of a job from its parts, once they have stopped.
SimResult finish_result(SimResult& result, const tables::PartTables& part, const control::Controller& controller,
                        const control::MachineSide& machine, const control::CommandedStock& model,
                        const stencil::sim::MachinedPart& machined,
                        const hal::cy545::Cy545Link& link, const control::MicrosecondHistogram& compute,
                        double simulated_s, std::chrono::steady_clock::time_point wall_start,
                        stencil::sim::SimulatedMill& mill, bool realtime) {
  result.rss_at_end_kb = resident_kb();
  result.max_rss_kb = max_resident_kb();
  stencil::sim::MachinedPart::Volumes volumes = machined.volumes();
  result.cycles = controller.statistics().cycles;
  result.overruns = controller.statistics().overruns;
  result.missed_periods = controller.statistics().missed_periods;
  // On virtual time every cycle starts on its deadline: no wake-up latency to speak of.
  result.wakeup_latency_us = realtime ? quantiles_of(controller.statistics().wakeup_latency) : Quantiles{0.0, 0.0, 0.0, 0.0};
  result.compute_us = quantiles_of(compute);
  result.simulated_s = simulated_s;
  result.gouge_max_depth_mm = machined.max_gouge_mm();
  result.gouge_measured = machined.gouge_measured();
  result.gouge_volume_mm3 = volumes.gouge_mm3;
  result.removed_volume_mm3 = volumes.removed_mm3;
  result.unmachined_volume_mm3 = volumes.unmachined_mm3;
  result.reachable_volume_mm3 = volumes.reachable_mm3;
  result.coverage_fraction = reachable_coverage(part, controller.touched());
  // Over the whole job: a resumed one's journal says what the runs before this one reached.
  result.max_force_n = std::max(controller.max_force_n(), result.earlier.max_force_n);
  result.max_offset_mm = std::max(controller.max_offset_mm(), result.earlier.max_offset_mm);
  result.machine_updates = machine.statistics().updates;
  result.machine_take_ups = machine.statistics().take_ups;
  result.machine_max_lag_mm = machine.statistics().max_lag_mm;
  result.safe_state = controller.safe_reason();
  if (machine.fault() != hal::MachineFault::None || machine.state() == control::MachineSideState::Stopped) {
    result.machine_error = link.last_error();
  }
  if (machine.stalled()) {
    result.machine_error = "the mill found no legal way along the virtual tool's path for 3 s (stalled)";
  }
  const stencil::sim::StockZmap& stock = machined.stock();
  result.columns = stock.columns();
  result.rows = stock.rows();
  result.cell_mm = stock.cell_mm();
  for (int row = 0; row < stock.rows(); ++row) {
    for (int column = 0; column < stock.columns(); ++column) {
      result.stock_heights.push_back(stock.height(column, row));
    }
  }
  result.part_heights = machined.part_heights();
  result.unmachined_heights = std::move(volumes.unmachined_per_cell_mm);
  // The controller's model beside the ground truth: each model cell against the mill's cell under
  // its centre.
  result.model_removed_volume_mm3 = model.removed_volume_mm3();
  for (int row = 0; row < model.rows(); ++row) {
    for (int column = 0; column < model.columns(); ++column) {
      const double x = model.block().low_mm.x() + (column + 0.5) * model.cell_mm();
      const double y = model.block().low_mm.y() + (row + 0.5) * model.cell_mm();
      const int c = std::clamp(static_cast<int>((x - stock.box().low_mm.x()) / stock.cell_mm()), 0, stock.columns() - 1);
      const int r = std::clamp(static_cast<int>((y - stock.box().low_mm.y()) / stock.cell_mm()), 0, stock.rows() - 1);
      result.model_max_difference_mm = std::max(result.model_max_difference_mm, std::abs(model.height(column, row) - stock.height(c, r)));
    }
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  mill.set_motion_observer(nullptr);
  return result;
}

SimResult run_job(const SimJob& job, const runtime::PeriodicRunner* runner) {
  const bool realtime = runner != nullptr;
  SimResult result;
  const tables::PartTables& part = *job.part;
  const auto wall_start = std::chrono::steady_clock::now();
  const motion::MachineFrames frames = sim::frames();

  // The far side of the serial cable: the mill, its fake CY545 on a pty, the clock they follow.
  stencil::sim::SimulatedMill mill{kMillConfig};
  const hal::MonotonicNs epoch_ns = realtime ? hal::posix_clock::monotonic_now_ns() : 0;
  stencil::sim::cy545::FakeCy545 fake{mill, kMmc4sWiring, epoch_ns};
  // Virtual time only: it gives the fake's bytes their wire time and its commands the chip's time,
  // which in real time the fake cannot know (a pty merges the driver's writes).
  std::optional<stencil::sim::cy545::FakeCy545Clock> fast_clock;
  if (!realtime) {
    fast_clock.emplace(fake, 0, kBaud);
  }
  hal::posix_clock::MonotonicClock wall_clock;
  hal::Clock& machine_clock = realtime ? static_cast<hal::Clock&>(wall_clock) : *fast_clock;
  fake.board().set_channel_latching(stencil::sim::cy545::ChannelLatching::Address);
  fake.chip().set_command_time_ns(0);  // see link_config.command_settle_ns
  // The rig's hardware watchdog relay on the heartbeat output (Mmc4sWiring::heartbeat_output).
  fake.board().arm_watchdog_relay(kMmc4sWiring.heartbeat_output, kWatchdogRelayNs, epoch_ns);
  stencil::sim::MachinedPart machined{part, job.stock, frames, [&fake, epoch_ns] {
                                        return static_cast<double>(fake.chip().now_ns() - epoch_ns) / 1e9;
                                      }};
  machined.set_trace(job.trace);
  mill.set_motion_observer(&machined);

  // The controller's side: the driver, the rings, the cycle and the machine side.
  hal::cy545::SerialPort port;
  char port_error[256] = {};
  if (!port.open(fake.slave_path().c_str(), kBaud, port_error)) {
    result.error = std::string("the fake CY545's pty: ") + port_error;
    return result;
  }
  const hal::cy545::Cy545Config link_config = sim::link_config(realtime);  // the rig's, but (sim_facts.hpp)
  hal::cy545::Cy545Link link(port, machine_clock, link_config);

  auto rings = std::make_unique<control::CycleRingStorage>();
  journal::JournalDrain records{job.journal, rings->commands};
  records.show_on(job.display);
  control::DisplayCommands display_commands;
  // The operator's hand, where the script starts, and the device it holds.
  stencil::sim::OperatorHand hand;
  hand.handle_mm = job.script.position_at(0.0);
  std::string wiring_error;
  SimulatedDeviceWiring device{job.transport, hand, wiring_error};
  if (!device.ready()) {
    result.error = "the simulated device's link: " + wiring_error;
    return result;
  }
  // The device in a process of its own: forked now, before any thread of this one starts.
  const double job_duration_s = job.duration_s > 0.0 ? job.duration_s : job.script.duration_s();
  DeviceProcess device_process;
  if (job.device_process_log != nullptr) {
    if (job.transport != HapticTransport::Pio || job.fault.kind != FaultKind::None) {
      result.error = "the device runs in its own process only over the PIO window, and with no fault injected";
      return result;
    }
    if (!device_process.start(*device.simulated(), hand, job.script, job_duration_s, !realtime, job.device_process_log)) {
      result.error = std::string("the device's process could not be started: ") + std::strerror(errno);
      return result;
    }
  }

  const control::ControllerConfig config = controller_config(realtime);
  // A replay's cycle reads the journal's device; any other's the simulated one.
  stencil::sim::ReplayHapticDevice replay_device;
  hal::HapticDevice& cycle_device = job.replay != nullptr ? static_cast<hal::HapticDevice&>(replay_device) : device.host();
  auto controller = std::make_unique<control::Controller>(part, cycle_device, rings->rings(), config);
  if (!controller->ready()) {
    result.error = "the tables' tool could not be grown for the touched set";
    return result;
  }
  const motion::PlannerLimits limits = kPlannerLimits;
  auto machine = std::make_unique<control::MachineSide>(part, link, frames, limits, rings->machine, rings->machine_events);
  // At the end, once the machine side has stopped the mill: its power as the board's latches leave
  // it, then a second later, when the watchdog relay (armed above) has dropped what the driver could
  // not turn off because its heartbeat stopped with the job. What the machinist finds at the mill.
  const auto leave_the_mill = [&](hal::MonotonicNs now_ns) {
    result.machine_stop_confirmed = machine->stop_confirmed();
    result.mill_spindle_on_after_stop = mill.spindle_on();
    result.mill_drivers_on_after_stop = mill.drivers_enabled();
    fake.board().advance_to(now_ns + kWatchdogRelayNs + 1'000'000);
    result.mill_relay_dropped_power = !fake.board().watchdog_relay_closed() &&
                                      (result.mill_spindle_on_after_stop || result.mill_drivers_on_after_stop);
    result.mill_on_after_relay = mill.spindle_on() || mill.drivers_enabled();
  };
  // The controller's own model of the stock, from the targets it sends (cells allocated here, once).
  const control::StockBlock block{job.stock.low_mm, job.stock.high_mm};
  std::vector<float> model_cells(control::CommandedStock::cells_needed(block, kModelCellMm));
  control::CommandedStock model(block, kModelCellMm, part.tool.spec, model_cells);
  machine->keep_stock_model(&model);
  // Every target is in the journal before it is sent. In real time the machine thread queues it for
  // the records thread, which writes it at once, and sends it when written (it never waits on the
  // journal's lock or disk); on virtual time one thread runs both and writes it through itself, so
  // it goes out in the same update (the same report and journal as ever).
  std::unique_ptr<journal::MachineJournal> machine_journal;
  std::unique_ptr<journal::InlineMachineJournal> inline_machine_journal;
  if (job.journal != nullptr && realtime) {
    machine_journal = std::make_unique<journal::MachineJournal>(*job.journal);
    machine->record_to(machine_journal.get());
  } else if (job.journal != nullptr) {
    inline_machine_journal = std::make_unique<journal::InlineMachineJournal>(*job.journal);
    machine->record_to(inline_machine_journal.get());
  }
  // A resumed job: what was touched and machined before, from the journal, before the machine homes.
  if (!job.resume_from.empty()) {
    const journal::HistoryRebuild rebuild{
        [&](const Eigen::Vector3d& tip) { controller->recall_touched(tip); },
        [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
          model.cut(from, to);
          machined.cut_recorded_leg(from, to);
        }};
    std::string history_error;
    if (!journal::read_job_history(job.resume_from, part.header.crc32, part.header.triangle_count, frames, rebuild,
                                   result.earlier, history_error, job.resume_bytes)) {
      result.error = "--resume: " + history_error;
      return result;
    }
    result.touched_rebuilt = static_cast<std::uint32_t>(controller->touched().count());
  }
  if (job.display != nullptr) {
    job.display->seed_touched(controller->touched());  // before the cycle runs: no race
  }
  // In real time the fake CY545 answers from a thread of its own; on virtual time it follows the
  // machine side's clock.
  std::unique_ptr<stencil::sim::cy545::FakeCy545Runner> fake_runner;
  if (realtime) {
    fake_runner = std::make_unique<stencil::sim::cy545::FakeCy545Runner>(fake);
  }
  // Wake-up and spindle in seconds; homing as long as the link says it can take.
  if (!machine->start(machine_clock.now_ns() + link.homing_bound_ns() + 20'000'000'000)) {
    result.error = machine->record_failed() ? "the machine did not start: its homing could not be journalled: " + job.journal->error()
                                            : std::string("the machine did not start: ") + link.last_error();
    return result;
  }
  result.started = true;
  result.rss_after_setup_kb = resident_kb();
  const auto arm = [&] {
    machined.arm({mill.axis_position_steps(stencil::sim::Axis::x), mill.axis_position_steps(stencil::sim::Axis::y),
                  mill.axis_position_steps(stencil::sim::Axis::z)});
  };
  if (realtime) {
    fake_runner->with_fake([&](stencil::sim::cy545::FakeCy545&) { arm(); });
  } else {
    arm();
  }

  // A replay ends with its records.
  const double duration_s = job.replay != nullptr ? std::numeric_limits<double>::infinity()
                            : job.duration_s > 0.0 ? job.duration_s
                                                   : job.script.duration_s();
  // After the script, the mill is given up to this long to catch up with the virtual tool.
  constexpr double kCatchUpS = 30.0;
  if (realtime) {
    std::atomic<bool> stop{false};
    std::atomic<bool> drained{false};
    std::string runner_error;
    hal::MonotonicNs start_ns = 0;
    std::thread machine_thread([&] {
      hal::MonotonicNs next = machine_clock.now_ns();
      while (!stop.load()) {
        machine_clock.sleep_until_ns(next);
        machine->update(std::max(next, machine_clock.now_ns()) + kUpdateBoundNs);
        fake_runner->with_fake([&](stencil::sim::cy545::FakeCy545&) { machined.flush(); });
        if (job.display != nullptr) {
          job.display->on_machine(machine->statistics().last_lag_mm, model);
        }
        drained.store(machine->path_left() <= 1 && machine->at_goal());
        next = std::max(next + kUpdateNs, machine_clock.now_ns());
      }
    });
    std::thread records_thread([&] {
      while (!stop.load()) {
        records.drain(rings->journal);
        records.sync_if_due();
        control::Telemetry frame{};
        while (rings->telemetry.pop(frame)) {
          if (job.display != nullptr) {
            job.display->on_telemetry(frame);
          }
        }
        display_commands.forward(job.display, rings->commands);
        if (job.interrupted != nullptr && job.interrupted->load()) {
          static_cast<void>(rings->commands.push({control::CommandKind::Stop}));
        }
        records.wait(std::chrono::milliseconds(50));  // or less: a target queued is written at once
      }
    });
    double next_progress_s = 10.0;
    const bool ran = (*runner)(
        kPeriodNs, stop,
        [&](hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) {
          if (start_ns == 0) {
            start_ns = deadline_ns;
          }
          const double t_s = static_cast<double>(now_ns - start_ns) / 1e9;
          // After the job's duration the hand holds still where the script had got to.
          if (!device_process.running()) {
            const double script_s = std::min(t_s, duration_s);
            hand.step(job.script.position_at(script_s), device.rendered_force());
            device.device_cycle(hand, job.script.angles_at(script_s), now_ns);
          }
          const control::CycleStatus status = controller->step(now_ns, deadline_ns);
          controller->finish(hal::posix_clock::monotonic_now_ns(), deadline_ns + kPeriodNs);
          if (status == control::CycleStatus::SafeState) {
            return false;
          }
          if (controller->statistics().cycles % 1000 != 0) {
            return true;
          }
          const double coverage = reachable_coverage(part, controller->touched());
          if (job.progress && t_s >= next_progress_s) {
            job.progress(t_s, coverage);
            next_progress_s += 10.0;
          }
          if (job.until_complete && coverage >= 1.0 && drained.load()) {
            result.complete = true;
            return false;
          }
          return !(t_s >= duration_s && (drained.load() || t_s >= duration_s + kCatchUpS));
        },
        runner_error);
    // One more update, so a safe state reaches the mill (hold, then stop), then everything stops.
    std::this_thread::sleep_for(std::chrono::milliseconds(2 * kUpdateNs / 1'000'000));
    stop.store(true);
    machine_thread.join();
    records_thread.join();
    records.drain(rings->journal);  // the last records, left after the records thread's last look
    machine->shut_down(machine_clock.now_ns() + kUpdateBoundNs);  // while the fake still answers
    fake_runner.reset();
    leave_the_mill(hal::posix_clock::monotonic_now_ns());
    if (!ran) {
      result.started = false;
      result.error = runner_error;
      return result;
    }
    machined.flush();
    return finish_result(result, part, *controller, *machine, model, machined, link, controller->statistics().compute,
                         static_cast<double>(hal::posix_clock::monotonic_now_ns() - start_ns) / 1e9,
                         wall_start, mill, true);
  }
  const hal::MonotonicNs start_ns = (machine_clock.now_ns() / kPeriodNs + 1) * kPeriodNs;
  hal::MonotonicNs cycle_ns = start_ns;
  hal::MonotonicNs next_update_ns = start_ns;
  control::MicrosecondHistogram compute;
  double next_progress_s = 10.0;
  bool stop_after_update = false;
  for (;;) {
    if (cycle_ns >= next_update_ns && cycle_ns >= machine_clock.now_ns()) {
      machine_clock.sleep_until_ns(cycle_ns);
      machine->update(machine_clock.now_ns() + kUpdateBoundNs);
      machined.flush();
      if (job.display != nullptr) {
        job.display->on_machine(machine->statistics().last_lag_mm, model);
      }
      if (machine->state() == control::MachineSideState::Stopped && result.machine_stopped_s < 0.0) {
        result.machine_stopped_s = static_cast<double>(cycle_ns - start_ns) / 1e9;
      }
      next_update_ns += kUpdateNs;
      // After a safe state: once the mill is stopped and the device is seen to drive no force (over a
      // wire it takes the zero command at its next millisecond), or a tenth of a second on.
      const double now_s = static_cast<double>(cycle_ns - start_ns) / 1e9;
      if (stop_after_update && (result.safe_state_s < 0.0 || result.force_zero_s >= 0.0 ||
                                now_s - result.safe_state_s > 0.1)) {
        break;
      }
      continue;
    }
    const double t_s = static_cast<double>(cycle_ns - start_ns) / 1e9;
    if (job.fault.kind != FaultKind::None && result.fault_injected_s < 0.0 && t_s >= job.fault.at_s) {
      inject(job.fault.kind, device, fake);
      controller->set_count_overruns(job.fault.kind == FaultKind::OverrunStorm);
      result.fault_kind = job.fault.kind;
      result.fault_injected_s = t_s;
    }
    // After the job's duration the hand holds still where the script had got to, while the mill
    // catches up: the same job always ends at the same place.
    const double script_s = std::min(t_s, duration_s);
    const control::JournalRecord* recorded = nullptr;
    if (job.replay != nullptr) {
      if (result.replay_cycles == job.replay->size()) {
        break;  // the record ends here, and so does the replay
      }
      recorded = &(*job.replay)[result.replay_cycles];
      replay_device.set(*recorded);
      // A safe state the device's read does not explain (the machine's fault, a stalled host, a
      // stop): the record says it came, so it comes here too, at the same cycle.
      if (recorded->safe_reason != control::SafeReason::None && controller->safe_reason() == control::SafeReason::None &&
          !control::is_device_reason(recorded->safe_reason)) {
        static_cast<void>(rings->commands.push({control::CommandKind::Stop}));
      }
    } else if (device_process.running()) {
      static_cast<void>(device_process.step(cycle_ns, script_s));  // no answer: no fresh sample, as from a hung device
    } else {
      hand.step(job.script.position_at(script_s), device.rendered_force());
      device.device_cycle(hand, job.script.angles_at(script_s), cycle_ns);
    }
    const auto wall_before = std::chrono::steady_clock::now();
    // An overrun storm: from the injection on, every cycle starts and ends 1.5 periods late, as on a
    // host that stalls the thread (lateness counts then, as on the wall clock).
    const hal::MonotonicNs late_ns = result.fault_kind == FaultKind::OverrunStorm ? 3 * kPeriodNs / 2 : 0;
    const control::CycleStatus status = controller->step(cycle_ns + late_ns, cycle_ns);
    compute.add(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - wall_before).count());
    controller->finish(cycle_ns + late_ns, cycle_ns + kPeriodNs);
    if (recorded != nullptr) {
      ++result.replay_cycles;
      const Eigen::Vector3d tip = controller->virtual_tip_mm();
      if (tip.x() != recorded->virtual_tip_mm[0] || tip.y() != recorded->virtual_tip_mm[1] ||
          tip.z() != recorded->virtual_tip_mm[2]) {
        if (result.replay_mismatches++ == 0) {
          result.replay_first_mismatch = static_cast<std::int64_t>(recorded->cycle);
        }
      }
      result.replay_recorded_reason = recorded->safe_reason;
    }
    // The overrun watchdog may enter the safe state in finish(): it counts from this cycle.
    const bool safe = status == control::CycleStatus::SafeState || controller->safe_reason() != control::SafeReason::None;
    if (safe && result.safe_state_s < 0.0) {
      result.safe_state_s = t_s;
    }
    if (result.safe_state_s >= 0.0 && result.force_zero_s < 0.0 &&
        (device_process.running() ? device_process.force_off() : device.force_off())) {
      result.force_zero_s = t_s;  // what the device drives: the command it took this cycle
    }
    records.drain(rings->journal);
    control::Telemetry frame{};
    while (rings->telemetry.pop(frame)) {
      if (job.display != nullptr) {
        job.display->on_telemetry(frame);
      }
    }
    if (job.display != nullptr && controller->statistics().cycles % 20 == 0) {
      display_commands.forward(job.display, rings->commands);
    }
    cycle_ns += kPeriodNs;
    if (safe) {
      if (!stop_after_update) {
        stop_after_update = true;
        // A machine update at once: it holds and stops the mill. Unless the safe state came in
        // finish() (the overrun watchdog): this cycle's handoff went without it, and only the next
        // cycle's carries it to the machine side (and its record to the journal).
        if (status == control::CycleStatus::SafeState) {
          next_update_ns = std::min(next_update_ns, cycle_ns);
        }
      }
      continue;
    }
    if (job.pace > 0.0 && controller->statistics().cycles % 10 == 0) {
      // Paced: no further ahead of the wall clock than `pace` simulated seconds per second.
      const auto due = wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>(t_s / job.pace));
      std::this_thread::sleep_until(due);
    }
    if (controller->statistics().cycles % 1000 == 0) {
      records.sync_if_due();
      if (job.interrupted != nullptr && job.interrupted->load()) {
        static_cast<void>(rings->commands.push({control::CommandKind::Stop}));  // taken by the next cycle
      }
      const double coverage = reachable_coverage(part, controller->touched());
      if (job.progress && t_s >= next_progress_s) {
        job.progress(t_s, coverage);
        next_progress_s += 10.0;
      }
      const bool drained = machine->path_left() <= 1 && machine->at_goal();
      if (job.until_complete && coverage >= 1.0 && drained) {
        result.complete = true;
        break;
      }
      if (t_s >= duration_s && (drained || t_s >= duration_s + kCatchUpS)) {
        break;
      }
    }
  }
  records.drain(rings->journal);
  machine->shut_down(machine_clock.now_ns() + kUpdateBoundNs);
  leave_the_mill(machine_clock.now_ns());
  machined.flush();
  return finish_result(result, part, *controller, *machine, model, machined, link, compute,
                       static_cast<double>(cycle_ns - start_ns) / 1e9, wall_start, mill, false);
}

}  // namespace

SimResult run_fast(const SimJob& job) { return run_job(job, nullptr); }

SimResult run_realtime(const SimJob& job, const runtime::PeriodicRunner& runner) { return run_job(job, &runner); }

}  // namespace stencil::board::sim
