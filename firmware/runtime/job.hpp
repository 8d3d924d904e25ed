// Job: one job assembled from a board's parts, the one place this happens: the cycle's rings, the
// controller, the machine side with the model of the stock it commands, the journal attached to
// both, and a resumed job's history rebuilt from its journal. Then the machine is started (homed,
// the spindle on) and the job is run: on threads in real time (runtime/threaded_run.hpp) or in
// virtual time (runtime/virtual_time_run.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/control/machine_record.hpp"
#include "firmware/core/control/machine_side.hpp"
#include "firmware/runtime/job_parts.hpp"
#include "firmware/runtime/run_outcome.hpp"
#include "firmware/services/report/job_report.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/journal/journal_drain.hpp"

namespace stencil::runtime {

// The machine side as a display shows it (the machine thread, after an update).
[[nodiscard]] inline control::MachineView view_of(const control::MachineSide& machine) {
  const Eigen::Vector3d& tip = machine.commanded_tip_mm();
  return {machine.statistics().last_lag_mm, {tip.x(), tip.y(), tip.z()}, machine.held()};
}

// How the machine is started once the job is assembled.
struct MachineStart {
  // Beyond the link's homing bound: the controller's wake-up and the spindle take seconds.
  hal::MonotonicNs homing_margin_ns = 20'000'000'000;
  // Once homed, each command's own bound (the spindle on, or the drivers off when the spindle is not
  // confirmed); 0: the homing's deadline covers the spindle too.
  hal::MonotonicNs after_homing_within_ns = 0;
  // Once homed, before the spindle starts: blocks until the operator confirms (true) or the job is
  // to end (false: the drivers go off, nothing is cut). Null: no confirmation.
  std::function<bool()> confirm_spindle;
};

// Why the machine did not start.
enum class StartFailure : std::uint8_t {
  None,
  HomingNotRecorded,    // the journal could not take the homing: nothing moved
  Homing,               // the link did not wake or home the mill
  SpindleNotConfirmed,  // the operator did not confirm the spindle: homed, drivers off
  Spindle,              // the link did not turn the spindle on
};

class Job {
 public:
  // Init time: assembles the job (see error()). The journal is attached for `timing`: in real time
  // the machine thread queues each target for the records thread, which writes it at once, and sends
  // it once written (it never waits on the journal's lock or disk); in virtual time one thread does
  // both, and each target is written as it is queued, so it goes out in the same update.
  Job(const JobParts& parts, Timing timing);
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;
  ~Job();

  // Empty when assembled; else why not (the tool could not be grown, the journal to resume from
  // could not be read or is another job's): do not run.
  [[nodiscard]] const std::string& error() const { return error_; }

  // Homes the machine (the homing in the journal first), then the spindle; blocks.
  [[nodiscard]] StartFailure start_machine(const MachineStart& start);
  // What a failure means for the operator, as the runtime words it.
  [[nodiscard]] std::string describe(StartFailure failure) const;

  [[nodiscard]] const JobParts& parts() const { return parts_; }
  [[nodiscard]] control::Controller& controller() { return *controller_; }
  [[nodiscard]] const control::Controller& controller() const { return *controller_; }
  [[nodiscard]] control::MachineSide& machine() { return *machine_; }
  [[nodiscard]] const control::MachineSide& machine() const { return *machine_; }
  [[nodiscard]] const control::CommandedStock& model() const { return *model_; }
  [[nodiscard]] control::CycleRingStorage& rings() { return *rings_; }
  [[nodiscard]] journal::JournalDrain& records() { return records_; }
  [[nodiscard]] const journal::JournalDrain& records() const { return records_; }
  [[nodiscard]] hal::Clock& machine_clock() const { return *parts_.machine_clock; }
  // A resumed job: the job before this run (earlier.segments 0: a fresh job), and the touched set's
  // size rebuilt from the virtual tool it recorded.
  [[nodiscard]] const journal::JobHistory& earlier() const { return earlier_; }
  [[nodiscard]] std::uint32_t touched_rebuilt() const { return touched_rebuilt_; }

 private:
  void attach_journal(Timing timing);
  [[nodiscard]] bool rebuild_from_journal();

  JobParts parts_;
  std::unique_ptr<control::CycleRingStorage> rings_;
  journal::JournalDrain records_;
  std::unique_ptr<control::Controller> controller_;
  std::unique_ptr<control::MachineSide> machine_;
  std::vector<float> model_cells_;  // allocated here, once
  std::unique_ptr<control::CommandedStock> model_;
  std::unique_ptr<journal::MachineJournal> machine_journal_;
  std::unique_ptr<journal::InlineMachineJournal> inline_machine_journal_;
  journal::JobHistory earlier_;
  std::uint32_t touched_rebuilt_ = 0;
  std::string error_;
};

// What the operator did in the run and where everything ended, for the job's report (after the run).
[[nodiscard]] report::OperatorRecord operator_record_of(const Job& job, const RunOutcome& outcome);

}  // namespace stencil::runtime
