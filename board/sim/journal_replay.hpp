// JournalReplay: one recorded run of a journal replayed (stencil-sim --replay): before each cycle the
// device gives exactly what the recorded cycle read and the cycle's command ring holds the commands
// the recorded cycle took (a stop, a reset, a pause, a parameter), and after it the virtual tool is
// compared with the recorded one, bit for bit (or with its recorded CRC-32, where a compact journal
// kept only that: a tool that differs anywhere in its 24 bytes is caught unless its CRC-32 collides,
// about one in four billion). The run ends with the records. A hook of the job's run, virtual
// time only.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "firmware/services/journal/cycle_codec.hpp"
#include "sim/haptic_device/replay_haptic_device.hpp"

namespace stencil::board::sim {

class JournalReplay final : public runtime::JobHooks {
 public:
  // Everything must outlive the replay; `device` is what the cycle reads, `commands` its command
  // ring (this hook pushes on the cycle's thread, which in virtual time is the ring's one producer).
  JournalReplay(const std::vector<journal::RecordedCycle>& records, const std::vector<control::CommandEvent>& taken,
                stencil::sim::ReplayHapticDevice& device, const control::Controller& controller,
                control::CommandRing& commands)
      : records_(records), taken_(taken), device_(device), controller_(controller), commands_(commands) {}

  bool before_cycle(const runtime::CycleTime& time) override;
  void after_cycle(const runtime::CycleTime& time, control::CycleStatus status) override;

  // Cycles compared, those whose virtual tool differs, the first of them (-1: none), and the safe
  // state the record ended in.
  [[nodiscard]] std::uint64_t cycles() const { return cycles_; }
  [[nodiscard]] std::uint64_t mismatches() const { return mismatches_; }
  [[nodiscard]] std::int64_t first_mismatch() const { return first_mismatch_; }
  [[nodiscard]] control::SafeReason recorded_reason() const { return recorded_reason_; }
  // Recorded commands that could not be given back (more in one cycle than the ring holds).
  [[nodiscard]] std::uint64_t commands_not_replayed() const { return commands_not_replayed_; }

 private:
  const std::vector<journal::RecordedCycle>& records_;
  const std::vector<control::CommandEvent>& taken_;  // in order: the cycles that took them rise
  std::size_t next_taken_ = 0;
  stencil::sim::ReplayHapticDevice& device_;
  const control::Controller& controller_;
  control::CommandRing& commands_;
  const journal::RecordedCycle* recorded_ = nullptr;  // this cycle's
  std::uint64_t cycles_ = 0;
  std::uint64_t mismatches_ = 0;
  std::int64_t first_mismatch_ = -1;
  control::SafeReason recorded_reason_ = control::SafeReason::None;
  std::uint64_t commands_not_replayed_ = 0;
};

}  // namespace stencil::board::sim
