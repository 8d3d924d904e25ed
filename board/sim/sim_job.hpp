// The host simulation's board: the simulated device (in process, over the PIO window or CAN), the fake
// CY545 on a pseudo-terminal, the simulated mill and its stock, and the simulated operator, handed to
// the runtime, which runs the job in virtual time (run_fast) or in real time (run_realtime).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "board/sim/fault_injection.hpp"
#include "board/sim/sim_facts.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/report/job_report.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "firmware/runtime/periodic_runner.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "hal/clock.hpp"
#include "hal/linuxcnc/linuxcnc_link.hpp"
#include "sim/mill/stock_zmap.hpp"
#include "sim/operator/hand_device_model.hpp"
#include "sim/operator/operator_script.hpp"

namespace stencil::board::sim {

// The simulation board's frames, speeds and the rest of its facts: sim_facts.hpp (the rig's).

// How the cycle reaches the simulated device: in process, or through the real backends' code over a
// memfd window (the PIO card's layout) or a socketpair carrying CAN frames.
struct LinuxcncMill {
  hal::linuxcnc::LinuxcncConfig link;
  std::string samples_path;
};

enum class HapticTransport : std::uint8_t { Direct, Pio, Can };

struct SimJob {
  SimRig rig;  // the configured rig and the simulated mill's truth (sim_facts.hpp)
  HapticTransport transport = HapticTransport::Direct;
  const tables::PartTables* part = nullptr;
  stencil::sim::StockBox stock{};
  stencil::sim::OperatorScript script;
  double duration_s = 0.0;      // 0: the script's own length
  bool until_complete = false;  // end once every reachable triangle is touched and the mill has caught up
  std::FILE* trace = nullptr;   // the mill's true path corners, t_s,x_mm,y_mm,z_mm
  std::function<void(double simulated_s, double coverage)> progress;  // about every 10 simulated s
  const std::atomic<bool>* interrupted = nullptr;  // set by SIGINT/SIGTERM: a stop command to the cycle
  journal::JournalWriter* journal = nullptr;  // every cycle's record and machine command goes here, when given (opened)
  // A resumed job: the journal of the job so far, read before the machine homes; the touched set and
  // the stock as machined are rebuilt from it and the result covers the whole job (`journal` then
  // carries on in the same file, opened to resume).
  std::string resume_from;
  std::size_t resume_bytes = 0;  // how much of it the job so far is (the file grows as this run carries on)
  FaultInjection fault;  // run_fast only
  // run_realtime over Pio only: the simulated device and the hand run in a forked process of their
  // own, which writes what its watchdog did when this process is gone to this file (null: in process).
  std::FILE* device_process_log = nullptr;
  // run_fast only: replay these recorded cycles (one run of a journal, in order) instead of the
  // operator and the device; each cycle reads exactly what the recorded one read. With resume_from
  // set to the runs before it, a resumed run is replayed from where it started.
  const std::vector<journal::RecordedCycle>* replay = nullptr;
  const std::vector<control::CommandEvent>* replay_commands = nullptr;  // the commands that run took (null: none)
  // run_fast only: at most this many simulated seconds per wall-clock second (0: as fast as it goes),
  // so a person can watch a deterministic run.
  double pace = 0.0;
  // An operator display (--hmi): fed from the records side and the machine side, never the cycle;
  // its requests go into the command ring.
  control::DisplayFeed* display = nullptr;
  // run_realtime only: the real LinuxCNC as the mill instead of the fake CY545 and its simulated mill
  // (sim/linuxcnc_mill runs one): the link's configuration, and the file halsampler writes every servo
  // period's joint positions to, the ground truth of what was machined.
  std::optional<LinuxcncMill> linuxcnc;
  // The operator's hand: kNoHand is today's placed hand (operator_script.hpp's OperatorHand); a preset
  // is the arm of hand_device_model.hpp pulling the handle, which has its own mass and friction.
  stencil::sim::HandParameters hand = stencil::sim::kNoHand;
  // The operator's commands before the first cycle (the wall's feel from the start): journalled and
  // taken like a display's. Not given to a replay, which has them from its journal.
  std::vector<control::Command> opening_commands;
};

using report::Quantiles;

// A G-code program's source line whose move would have taken the tool into the part: the stencil
// refused or shortened it (gcode_job.hpp). depth_mm: the deepest its move would have gone.
struct GcodeRefusal {
  int line;
  double depth_mm;
};

struct SimResult {
  bool started = false;          // false: the machine never came up (see error)
  std::string error;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::uint64_t missed_periods = 0;  // skipped after the cycle woke too late for them (real time)
  Quantiles wakeup_latency_us{};  // on virtual time: always 0
  Quantiles compute_us{};         // wall clock: the cycle's own work
  double simulated_s = 0.0;
  double wall_s = 0.0;
  double gouge_max_depth_mm = 0.0;
  bool gouge_measured = false;
  double gouge_volume_mm3 = 0.0;
  double removed_volume_mm3 = 0.0;
  double unmachined_volume_mm3 = 0.0;
  double reachable_volume_mm3 = 0.0;
  double allowance_volume_mm3 = 0.0;   // left on the part by the controller's standoff (not unmachined)
  double standoff_mm = 0.0;            // that standoff
  double coverage_fraction = 0.0;  // reachable triangles touched
  double max_force_n = 0.0;
  double max_offset_mm = 0.0;
  std::uint64_t machine_updates = 0;
  std::uint64_t machine_take_ups = 0;
  double machine_max_lag_mm = 0.0;
  control::SafeReason safe_state = control::SafeReason::None;
  std::string machine_error;  // the machine link's last error, when it faulted
  // At the end: did the link confirm spindle and drivers off; the simulated mill's power once the
  // machine side stopped it (the board's latches); whether the watchdog relay had to drop it a
  // second later (the heartbeat stopped with the job); and whether anything is on even then.
  bool machine_stop_confirmed = false;
  bool mill_spindle_on_after_stop = false;
  bool mill_drivers_on_after_stop = false;
  bool mill_relay_dropped_power = false;
  bool mill_on_after_relay = false;
  bool complete = false;  // until_complete met
  // The injected fault and what followed, simulated seconds (negative: never happened).
  FaultKind fault_kind = FaultKind::None;
  double fault_injected_s = -1.0;
  double safe_state_s = -1.0;       // the first cycle in the safe state
  double force_zero_s = -1.0;       // from then, the first cycle the device drove no force
  double machine_stopped_s = -1.0;  // the machine update that held and stopped the mill
  double model_removed_volume_mm3 = 0.0;  // the controller's own model of the stock (what it commanded)
  double model_max_difference_mm = 0.0;   // the most it differs from the mill's stock over any cell
  std::string journal_path;     // empty: no journal
  std::uint64_t journal_records = 0;
  std::uint64_t journal_machine_records = 0;
  std::uint64_t journal_command_records = 0;
  std::string journal_error;    // why the journal stopped, when it could not be written
  // The job before this run, from the journal it resumed (earlier.segments 0: a fresh job), and the
  // touched set's size the journal recorded against the one rebuilt from its virtual tool.
  journal::JobHistory earlier;
  // A replay: cycles compared with the record, those whose virtual tool differs (bit for bit), the
  // first of them (-1: none), and the safe state the record ended in.
  std::uint64_t replay_cycles = 0;
  std::uint64_t replay_mismatches = 0;
  std::int64_t replay_first_mismatch = -1;
  control::SafeReason replay_recorded_reason = control::SafeReason::None;
  std::uint64_t replay_commands_not_given = 0;
  std::uint32_t touched_rebuilt = 0;
  // A G-code program as the operator (--gcode-operator) or cut directly (--gcode-direct): its path
  // ("" for neither), and the lines the stencil refused or shortened (the operator's only).
  std::string gcode_program;
  bool gcode_direct = false;
  std::vector<GcodeRefusal> gcode_refused;
  report::OperatorRecord operator_record;  // what the operator did, where everything ended
  // Memory: resident once the job was set up (the journal rebuilt, the machine homed), at its end,
  // and the most it ever was (kB).
  std::int64_t rss_after_setup_kb = 0;
  std::int64_t rss_at_end_kb = 0;
  std::int64_t max_rss_kb = 0;
  // The machined stock, the part's top and what is left to cut, for the picture: heights per cell, row-major.
  int columns = 0, rows = 0;
  double cell_mm = 0.0;
  std::vector<double> stock_heights, part_heights;
  std::vector<double> unmachined_heights;  // stock this tool could still remove over each cell, mm thick
  // From each cell's top (its centre at its stock height) to the part's surface, mm: negative inside
  // the part, exact within kSignedDistanceReachMm and clamped to it beyond (the picture's colours).
  std::vector<float> signed_distance_mm;
};

// How far the signed distances of the stock's cells are exact (mm): as far as the picture's blue
// scale of stock left goes; farther cells are clamped to it, which keeps the end of a job quick.
inline constexpr double kSignedDistanceReachMm = 2.0;

// Runs the job on virtual time, as fast as the machine allows; the same job gives the same result
// apart from the wall-clock fields (compute_us, wall_s).
[[nodiscard]] SimResult run_fast(const SimJob& job);

// Runs the job in real time: the cycle on `runner`'s thread each millisecond, the machine side on a
// thread of its own at the update rate, the fake CY545 serviced on the pty in real time, the journal
// and telemetry drained at 20 Hz; overruns count.
[[nodiscard]] SimResult run_realtime(const SimJob& job, const runtime::PeriodicRunner& runner);

// The lowest the part's tool can have its tip over (x, y) without entering the part, from the
// part's top over a 0.05 mm grid of the stock (the scripted operator's idea of the part).
[[nodiscard]] std::function<double(double, double)> touch_tip_of(const tables::PartTables& part,
                                                                  const stencil::sim::StockBox& stock);

// The cycle's configuration in the simulation (frames, reach, the mill's speed; overruns count in
// real time only).
[[nodiscard]] control::ControllerConfig controller_config(bool realtime, const SimRig& rig = {});

// The simulation board's device -> world -> machine frames (above), as the controller believes them.
[[nodiscard]] motion::MachineFrames frames(const SimRig& rig = {});
// The same with the simulated mill's true steps per mm and axis signs: where its steps really put the tool.
[[nodiscard]] motion::MachineFrames true_frames(const SimRig& rig);

// The default stock for a part: its bounding box grown by 2 mm on each side in x and y (within the
// workspace), from the floor to 1 mm above the part's top.
[[nodiscard]] stencil::sim::StockBox default_stock(const tables::PartTables& part);

}  // namespace stencil::board::sim
