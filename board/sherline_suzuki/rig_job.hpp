// The rig's run: the controller's cycle on the real-time runner, the machine side on a thread of its
// own at the update rate, and a records thread (journal, progress, signals), wired to whatever
// haptic device and machine link the caller opened: the PIO card or SocketCAN and the CY545 on
// the rig, the fakes in the tests. The frames are the rig's, shifted by the work offset.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "firmware/services/report/job_report.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/runtime/periodic_runner.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "hal/clock.hpp"
#include "hal/haptic_device.hpp"
#include "hal/machine_link.hpp"

namespace stencil::board::sherline_suzuki {

// Where the tool tip is in the world (the part's coordinates) when the machine is at home, from the
// touch-off, and the tool's stick-out below the holder against the one the touch-off was made with.
struct WorkOffset {
  Eigen::Vector3d home_world_mm{kHomeWorldMm[0], kHomeWorldMm[1], kHomeWorldMm[2]};  // the workspace's far top corner
  double tool_stick_out_mm = 0.0;                   // 0: the touch-off's own tool
  double reference_stick_out_mm = 0.0;
};

// The rig's frames: world = device / 10, every axis counting into the workspace from its switch;
// a tool that sticks out further puts the tip lower at home.
[[nodiscard]] motion::MachineFrames rig_frames(const WorkOffset& offset, const RigFacts& facts = kRig);

struct RigJob {
  RigFacts facts = kRig;                // the rig: compiled in, or from its configuration file (rig_config.hpp)
  const tables::PartTables* part = nullptr;
  hal::HapticDevice* device = nullptr;
  double device_delay_s = 0.0;          // its link's command-to-motor delay (hal::kPioCommandDelayS, ...)
  hal::MachineLink* machine = nullptr;
  hal::Clock* machine_clock = nullptr;  // the link's clock: the machine thread paces on it
  WorkOffset offset;
  control::StockBlock stock{};          // for the controller's model of the machined stock
  journal::JournalWriter* journal = nullptr;  // every cycle's record and machine command goes here, when given
  // A resumed job: its journal's first resume_bytes (the job so far). The touched set and the model
  // of the machined stock are rebuilt from it before the machine homes again.
  std::string resume_from;
  std::size_t resume_bytes = 0;
  // SIGINT, SIGTERM, SIGHUP, SIGQUIT: a stop command to the cycle, and homing given up between commands.
  const std::atomic<bool>* interrupted = nullptr;
  double duration_s = 0.0;                          // 0: until interrupted or a safe state
  std::function<void(const std::string&)> progress;  // a line about every second, and every event
  // Once homed, before the spindle starts: blocks until the operator confirms (true) or the job is
  // to end (false: the mill stays homed with the spindle off and the run ends). Null: no confirmation.
  std::function<bool()> confirm_spindle;
  // Polled by the records thread: a command the operator typed at the terminal (stop, pause,
  // resume, reset), or nothing.
  std::function<std::optional<control::CommandKind>()> operator_command;
  // Run first on the machine thread, before its first update: stencil-rig gives it SCHED_FIFO below
  // the cycle and above the records thread (app::run_this_thread_fifo); none in the tests.
  std::function<void()> prepare_machine_thread;
  // An operator display (--hmi): fed by the records and machine threads, never the cycle; its
  // requests (parameters, reset) go into the command ring from the records thread.
  control::DisplayFeed* display = nullptr;
};

struct RigResult {
  bool started = false;
  std::string error;
  std::uint64_t cycles = 0, overruns = 0, missed_periods = 0;
  report::Quantiles wakeup_latency_us{};
  report::Quantiles compute_us{};
  double max_force_n = 0.0, max_offset_mm = 0.0;
  std::uint64_t machine_updates = 0;
  bool machine_stop_confirmed = false;  // the link confirmed spindle and drivers off at the end
  std::string machine_stall;            // the mill found no way for 3 s: where, and what was tried ("" otherwise)
  double machine_max_lag_mm = 0.0;
  double model_removed_mm3 = 0.0;
  double run_s = 0.0;
  control::SafeReason safe_state = control::SafeReason::None;  // at the end (stopped: as asked)
  control::SafeReason first_fault = control::SafeReason::None;  // the first safe state not asked for
  std::uint64_t safe_state_entries = 0;
  std::uint64_t resets_accepted = 0, resets_refused = 0;
  std::string journal_error;
  journal::JobHistory earlier;        // the job before this run (earlier.segments 0: a fresh job)
  std::uint32_t touched_rebuilt = 0;  // the touched set rebuilt from it (earlier.touched_recorded: as recorded)
  report::OperatorRecord operator_record;  // what the operator did, where everything ended
};

// Homes the machine (a resumed job: after rebuilding what the journal says was touched and cut), then
// runs until the duration or an interrupt; on the way out the machine is held and stopped. A fault's
// safe state (zero force, the mill held and stopped) keeps the cycle running until a reset restores
// the force (the mill stays stopped: carrying on means a new run with --resume, which homes again)
// or the run is stopped. Blocks.
// The cycle's configuration for this job (frames, reach, speed limit, watchdogs), as run_rig uses it.
[[nodiscard]] control::ControllerConfig rig_controller_config(const RigJob& job);

[[nodiscard]] RigResult run_rig(const RigJob& job, const runtime::PeriodicRunner& runner);

}  // namespace stencil::board::sherline_suzuki
