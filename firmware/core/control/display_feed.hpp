// DisplayFeed: what the threads around the cycle tell an operator display (the journal records and
// the commands the cycle took as they are drained, the telemetry, the machine side's position, lag
// and stock model), and the ring the display's requests go into. The display is never called from
// the cycle: a board's records thread and machine thread call it, so a slow display cannot delay a
// period; the cycle only pops the display's ring, as it pops its own.
#pragma once

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/stencil/triangle_set.hpp"

namespace stencil::control {

// The machine side as a display shows it, at each update.
struct MachineView {
  double lag_mm;                 // the virtual tool to the mill's newest target, world
  double commanded_tip_mm[3];    // where the last target sent puts the tool tip, world (work) mm
  bool held;                     // the operator's feed hold is on at the link
};

class DisplayFeed {
 public:
  virtual void on_record(const JournalRecord& record) = 0;        // every record, in order
  virtual void on_command(const CommandEvent& event) = 0;         // every command the cycle took, in order
  virtual void on_telemetry(const Telemetry& telemetry) = 0;
  virtual void on_machine(const MachineView& machine, const CommandedStock& model) = 0;  // the machine side's thread
  virtual void seed_touched(const engine::TriangleSet& touched) = 0;       // before the cycle starts
  // The display's requests go straight into this ring (its own server thread is the one producer),
  // which the cycle drains with its own: a Stop is taken by the next cycle. Lives as long as the feed.
  [[nodiscard]] virtual CommandRing& commands() = 0;

 protected:
  ~DisplayFeed() = default;
};

}  // namespace stencil::control
