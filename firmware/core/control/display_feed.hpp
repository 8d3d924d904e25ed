// DisplayFeed: what the threads around the cycle tell an operator display (the journal records as
// they are drained, the telemetry, the machine side's lag and stock model) and the display's
// requests they forward into the cycle's command ring. The display is never called from the cycle:
// a board's records thread and machine thread call it, so a slow display cannot delay a period.
#pragma once

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/stencil/triangle_set.hpp"

namespace stencil::control {

class DisplayFeed {
 public:
  virtual void on_record(const JournalRecord& record) = 0;        // every record, in order
  virtual void on_telemetry(const Telemetry& telemetry) = 0;
  virtual void on_machine(double lag_mm, const CommandedStock& model) = 0;  // from the machine side's thread
  virtual void seed_touched(const engine::TriangleSet& touched) = 0;       // before the cycle starts
  [[nodiscard]] virtual bool pop_command(Command& command) = 0;

 protected:
  ~DisplayFeed() = default;
};

// The display's requests into the command ring, on the ring's one producer's thread. A request the
// full ring cannot take now waits here for the next call.
class DisplayCommands {
 public:
  void forward(DisplayFeed* display, CommandRing& ring) {
    if (display == nullptr) {
      return;
    }
    for (std::size_t i = 0; i < CommandRing::capacity(); ++i) {
      if (!held_ && !display->pop_command(command_)) {
        return;
      }
      held_ = !ring.push(command_);
      if (held_) {
        return;
      }
    }
  }

 private:
  Command command_{};
  bool held_ = false;
};

}  // namespace stencil::control
