// A recorded run, cycle by cycle.
#include "board/sim/journal_replay.hpp"

#include <cstring>

#include "firmware/core/control/safe_state.hpp"

namespace stencil::board::sim {

bool JournalReplay::before_cycle(const runtime::CycleTime& /*time*/) {
  if (cycles_ == records_.size()) {
    return false;  // the record ends here, and so does the replay
  }
  recorded_ = &records_[cycles_];
  const control::JournalRecord& recorded = recorded_->record;
  device_.set(recorded);
  // The commands this cycle took, as they came (a command taken before the first record: at once).
  bool stopped = false;
  for (; next_taken_ < taken_.size() && taken_[next_taken_].cycle <= recorded.cycle; ++next_taken_) {
    const control::CommandEvent& event = taken_[next_taken_];
    stopped = stopped || event.kind == control::CommandKind::Stop || event.kind == control::CommandKind::JournalFailed;
    if (!commands_.push({event.kind, event.asked, event.source})) {
      ++commands_not_replayed_;
    }
  }
  // A safe state the device's read and the commands do not explain (the machine's fault, a stalled
  // host, a journal without command records): the record says it came, so it comes here too.
  if (!stopped && recorded.safe_reason != control::SafeReason::None &&
      controller_.safe_reason() == control::SafeReason::None && !control::is_device_reason(recorded.safe_reason)) {
    static_cast<void>(commands_.push({control::CommandKind::Stop, 0.0, control::CommandSource::Replay}));
  }
  return true;
}

void JournalReplay::after_cycle(const runtime::CycleTime& /*time*/, control::CycleStatus /*status*/) {
  ++cycles_;
  const Eigen::Vector3d tip = controller_.virtual_tip_mm();
  const control::JournalRecord& recorded = recorded_->record;
  const double replayed[3] = {tip.x(), tip.y(), tip.z()};
  // Bit for bit where the tip was kept (-0 is not +0, a NaN is itself), else its CRC-32.
  const bool same = recorded_->tool_recorded ? std::memcmp(replayed, recorded.virtual_tip_mm, sizeof replayed) == 0
                                             : journal::tip_check(replayed) == recorded_->tip_check;
  if (!same && mismatches_++ == 0) {
    first_mismatch_ = static_cast<std::int64_t>(recorded.cycle);
  }
  recorded_reason_ = recorded.safe_reason;
}

}  // namespace stencil::board::sim
