// JournalDrain: the records thread's loop body. The machine thread's targets go to the journal file
// first (the machine side holds the newest until it is there), then every record the cycle left in
// its journal ring (when there is a file); a record that cannot be written asks the cycle to stop,
// once, on its command ring: the record must lose nothing. The thread that drains is the command
// ring's one producer. Between looks, wait() returns early when the machine thread queues a target.
#pragma once

#include <chrono>
#include <thread>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/services/journal/journal_writer.hpp"

namespace stencil::journal {

class JournalDrain {
 public:
  JournalDrain(JournalWriter* writer, control::CommandRing& commands) : writer_(writer), commands_(commands) {}

  void drain(control::JournalRing& ring) {
    if (writer_ != nullptr && !failed_ && !writer_->write_machine_commands()) {
      failed_ = true;
    }
    control::JournalRecord record{};
    while (ring.pop(record)) {
      if (display_ != nullptr) {
        display_->on_record(record);
      }
      if (writer_ != nullptr && !failed_ && !writer_->append(record)) {
        failed_ = true;
      }
    }
    tell_the_cycle();
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
  // Until the cycle has the news: a full command ring is tried again at the next look.
  void tell_the_cycle() {
    if (failed_ && !told_) {
      told_ = commands_.push({control::CommandKind::JournalFailed});
    }
  }

  JournalWriter* writer_;
  control::CommandRing& commands_;
  control::DisplayFeed* display_ = nullptr;
  bool failed_ = false;
  bool told_ = false;
};

}  // namespace stencil::journal
