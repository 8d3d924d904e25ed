// A job's assembly from a board's parts, the resume rebuild and the machine's start.
#include "firmware/runtime/job.hpp"

namespace stencil::runtime {

Job::Job(const JobParts& parts, Timing timing)
    : parts_(parts), rings_(std::make_unique<control::CycleRingStorage>()), records_(parts.journal, rings_->commands) {
  const tables::PartTables& part = *parts_.part;
  records_.show_on(parts_.display);
  records_.take_commands_from(&rings_->command_events);
  // The controller is large (the touched set): on the heap, as the machine side.
  controller_ = std::make_unique<control::Controller>(part, *parts_.device, rings_->rings(parts_.display != nullptr ? &parts_.display->commands() : nullptr), parts_.controller);
  if (!controller_->ready()) {
    error_ = "the tables' tool could not be grown for the touched set";
    return;
  }
  machine_ = std::make_unique<control::MachineSide>(part, *parts_.machine, parts_.controller.frames, parts_.planner,
                                                    rings_->machine, rings_->machine_events);
  model_cells_.resize(control::CommandedStock::cells_needed(parts_.stock, parts_.model_cell_mm));
  model_ = std::make_unique<control::CommandedStock>(parts_.stock, parts_.model_cell_mm, part.tool.spec, model_cells_);
  if (model_->ready()) {
    machine_->keep_stock_model(model_.get());
  }
  attach_journal(timing);
  // What was touched and machined before, from the journal, before the machine homes.
  if (!parts_.resume_from.empty() && !rebuild_from_journal()) {
    return;
  }
  if (parts_.display != nullptr) {
    parts_.display->seed_touched(controller_->touched());  // before the cycle runs: no race
  }
}

Job::~Job() = default;

void Job::attach_journal(Timing timing) {
  // Every target is in the journal before it is sent (see the constructor's comment for how).
  if (parts_.journal == nullptr) {
    return;
  }
  if (timing == Timing::RealTime) {
    machine_journal_ = std::make_unique<journal::MachineJournal>(*parts_.journal);
    machine_->record_to(machine_journal_.get());
  } else {
    inline_machine_journal_ = std::make_unique<journal::InlineMachineJournal>(*parts_.journal);
    machine_->record_to(inline_machine_journal_.get());
  }
}

bool Job::rebuild_from_journal() {
  const tables::PartTables& part = *parts_.part;
  const journal::HistoryRebuild rebuild{
      [this](const Eigen::Vector3d& tip) { controller_->recall_touched(tip); },
      [this](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
        model_->cut(from, to);
        if (parts_.recorded_leg) {
          parts_.recorded_leg(from, to);
        }
      }};
  std::string history_error;
  if (!journal::read_job_history(parts_.resume_from, part.header.crc32, part.header.triangle_count,
                                 parts_.controller.frames, rebuild, earlier_, history_error, parts_.resume_bytes)) {
    error_ = "--resume: " + history_error;
    return false;
  }
  touched_rebuilt_ = static_cast<std::uint32_t>(controller_->touched().count());
  return true;
}

StartFailure Job::start_machine(const MachineStart& start) {
  hal::Clock& clock = *parts_.machine_clock;
  // Homing as long as the link says it can take from anywhere, and the margin for the rest.
  const hal::MonotonicNs homing_deadline_ns = clock.now_ns() + parts_.machine->homing_bound_ns() + start.homing_margin_ns;
  if (!machine_->home(homing_deadline_ns)) {
    return machine_->record_failed() ? StartFailure::HomingNotRecorded : StartFailure::Homing;
  }
  if (start.confirm_spindle && !start.confirm_spindle()) {
    static_cast<void>(parts_.machine->stop(clock.now_ns() + start.after_homing_within_ns));  // nothing runs unattended
    return StartFailure::SpindleNotConfirmed;
  }
  const hal::MonotonicNs spindle_deadline_ns =
      start.after_homing_within_ns > 0 ? clock.now_ns() + start.after_homing_within_ns : homing_deadline_ns;
  if (!machine_->start_spindle(spindle_deadline_ns)) {
    return StartFailure::Spindle;
  }
  return StartFailure::None;
}

std::string Job::describe(StartFailure failure) const {
  switch (failure) {
    case StartFailure::None:
      return "";
    case StartFailure::HomingNotRecorded:
      return "the machine did not start: its homing could not be journalled: " + parts_.journal->error();
    case StartFailure::Homing:
      return "the machine did not start (wake, home)";
    case StartFailure::SpindleNotConfirmed:
      return "the spindle was not confirmed: nothing was cut";
    case StartFailure::Spindle:
      return "the machine did not start (spindle on)";
  }
  return "";
}

report::OperatorRecord operator_record_of(const Job& job, const RunOutcome& outcome) {
  report::OperatorRecord r;
  const control::ControllerConfig& config = job.parts().controller;
  r.commands = job.records().commands();
  r.commands_unlisted = job.records().commands_unlisted();
  r.initial_limits = {config.haptic.coupling_n_per_device_mm, config.haptic.max_force_n,
                      config.max_axis_move_mm / config.period_s, config.feel.damping_n_s_per_m, config.feel.friction,
                      config.feel.speed_limiting};
  r.start_ns = outcome.start_ns;
  r.period_s = config.period_s;
  r.machine_holds = job.machine().statistics().holds;
  r.machine_held_updates = job.machine().statistics().held_updates;
  r.safe_source = job.controller().safe_source();
  // The newest record is what a display showed last: the same figures here.
  control::JournalRecord last{};
  const bool have = job.records().last_record(last);
  const Eigen::Vector3d device = have ? Eigen::Vector3d(last.device_mm[0], last.device_mm[1], last.device_mm[2])
                                      : Eigen::Vector3d::Zero();
  const Eigen::Vector3d tip = job.controller().virtual_tip_mm();
  const Eigen::Vector3d tip_machine = motion::world_to_machine_mm(config.frames, tip);
  const Eigen::Vector3d mill = job.machine().commanded_tip_mm();
  const Eigen::Vector3d mill_machine = motion::world_to_machine_mm(config.frames, mill);
  for (int i = 0; i < 3; ++i) {
    r.positions.device_mm[i] = device[i];
    r.positions.virtual_work_mm[i] = tip[i];
    r.positions.virtual_machine_mm[i] = tip_machine[i];
    r.positions.mill_work_mm[i] = mill[i];
    r.positions.mill_machine_mm[i] = mill_machine[i];
  }
  return r;
}

}  // namespace stencil::runtime
