// What the machine thread records before it acts, so that what was machined survives a crash of
// the controller: the homing, and every target with its step position, before it is sent (a
// command in the record may not have been sent; one that was sent is always in the record).
#pragma once

#include <cstdint>

namespace stencil::control {

struct MachineCommandRecord {
  std::uint64_t update;            // the machine update that sent it (targets sent so far)
  std::int64_t time_ns;            // the update's deadline, on the machine's clock
  std::int32_t motor_target[3];    // the steps sent per axis, backlash take-up included
  std::uint8_t order[3];           // the axes' legs in this order (3: no leg)
  double target_tip_mm[3];         // where the tool's tip goes (world), the legs' common end
};

// The machine side's record (the journal). homed() is called by start(), before the machine thread
// runs, and may block until the homing is in the record (false: not recorded, nothing moves).
// command() and written() are called by the machine thread at its updates and never block on the
// record's storage (real-time safe): command() queues a target (false: it cannot be recorded, and
// it is not sent: a journal fault); written() says whether every target queued so far is in the
// record. The machine side sends a target only once it is written, and holds the mill until then:
// a target that was sent is always in the record, so a crash of the program cannot lose what was
// machined (issue 18, item 10: the machine thread no longer waits on the journal's writes).
class MachineRecorder {
 public:
  [[nodiscard]] virtual bool homed(std::int64_t time_ns) = 0;
  [[nodiscard]] virtual bool command(const MachineCommandRecord& record) = 0;
  [[nodiscard]] virtual bool written() const = 0;

 protected:
  ~MachineRecorder() = default;
};

}  // namespace stencil::control
