// JournalDrain: the records thread's loop body. The machine thread's targets go to the journal file
// first (the machine side holds the newest until it is there), then every record the cycle left in
// its journal ring (when there is a file), each after the commands its cycle took (their own records); a record that cannot be written asks the cycle to stop,
// once, on its command ring: the record must lose nothing. The thread that drains is the command
// ring's one producer. Between looks, wait() returns early when the machine thread queues a target.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/services/journal/journal_writer.hpp"

namespace stencil::journal {

class JournalDrain {
 public:
  JournalDrain(JournalWriter* writer, control::CommandRing& commands) : writer_(writer), cycle_commands_(commands) {}

  // `last`: the run is over, so the commands taken after the last cycle record go too.
  void drain(control::JournalRing& ring, bool last = false) {
    if (writer_ != nullptr && !failed_ && !writer_->write_machine_commands()) {
      failed_ = true;
    }
    control::JournalRecord record{};
    while (ring.pop(record)) {
      last_record_ = record;
      have_record_ = true;
      take_commands_up_to(record.cycle);  // a command goes before the record of the cycle that took it
      if (display_ != nullptr) {
        display_->on_record(record);
      }
      if (writer_ != nullptr && !failed_ && !writer_->append(record)) {
        failed_ = true;
      }
    }
    if (last) {
      take_commands_up_to(std::numeric_limits<std::uint64_t>::max());
    }
    tell_the_cycle();
  }

  // The cycle's commands, each in its cycle's place among the records (set before the first drain).
  void take_commands_from(control::CommandEventRing* ring) { command_events_ = ring; }

  // Every command the cycle took, in order, for the report: the first kMaxListed (the rest counted).
  static constexpr std::size_t kMaxListed = 10000;
  [[nodiscard]] const std::vector<control::CommandEvent>& commands() const { return commands_; }
  [[nodiscard]] std::uint64_t commands_unlisted() const { return commands_unlisted_; }
  // The newest record drained (false: none yet).
  [[nodiscard]] bool last_record(control::JournalRecord& record) const {
    record = last_record_;
    return have_record_;
  }

  void sync_if_due() {
    const auto now = std::chrono::steady_clock::now().time_since_epoch();
    if (writer_ != nullptr && !failed_ &&
        !writer_->sync_if_due(std::chrono::duration_cast<std::chrono::nanoseconds>(now).count())) {
      failed_ = true;
    }
    tell_the_cycle();
  }

  // Between looks (instead of sleeping `most`): back as soon as the machine thread has queued a
  // target, so that it is written before the machine side's next update, which sends it.
  void wait(std::chrono::nanoseconds most) {
    if (writer_ != nullptr) {
      writer_->wait_for_machine_commands(most);
    } else {
      std::this_thread::sleep_for(most);
    }
  }

  [[nodiscard]] bool failed() const { return failed_; }

  // An operator display also sees every record drained (none by default).
  void show_on(control::DisplayFeed* display) { display_ = display; }

 private:
  void take_commands_up_to(std::uint64_t cycle) {
    if (command_events_ == nullptr) {
      return;
    }
    for (;;) {
      if (!have_pending_ && !command_events_->pop(pending_)) {
        return;
      }
      have_pending_ = true;
      if (pending_.cycle > cycle) {
        return;  // its cycle's record is not out yet
      }
      have_pending_ = false;
      if (commands_.size() < kMaxListed) {
        commands_.push_back(pending_);
      } else {
        ++commands_unlisted_;
      }
      if (display_ != nullptr) {
        display_->on_command(pending_);
      }
      if (writer_ != nullptr && !failed_ && !writer_->append_command(pending_)) {
        failed_ = true;
      }
    }
  }

  // Until the cycle has the news: a full command ring is tried again at the next look.
  void tell_the_cycle() {
    if (failed_ && !told_) {
      told_ = cycle_commands_.push({control::CommandKind::JournalFailed, 0.0, control::CommandSource::Program});
    }
  }

  JournalWriter* writer_;
  control::CommandRing& cycle_commands_;
  control::DisplayFeed* display_ = nullptr;
  control::CommandEventRing* command_events_ = nullptr;
  control::CommandEvent pending_{};
  control::JournalRecord last_record_{};
  bool have_record_ = false;
  bool have_pending_ = false;
  std::vector<control::CommandEvent> commands_;
  std::uint64_t commands_unlisted_ = 0;
  bool failed_ = false;
  bool told_ = false;
};

}  // namespace stencil::journal
