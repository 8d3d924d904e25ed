// An injected fault, where it happens.
#include "board/sim/fault_injector.hpp"

namespace stencil::board::sim {

bool FaultInjector::before_cycle(const runtime::CycleTime& time) {
  if (fault_.kind == FaultKind::None || injected_s_ >= 0.0 || !(time.t_s >= fault_.at_s)) {
    return true;
  }
  switch (fault_.kind) {
    case FaultKind::Cy545Silent:
      fake_.set_replies_suppressed(true);
      break;
    case FaultKind::Cy545Garbled:
      fake_.set_replies_garbled(true);
      break;
    case FaultKind::SerialGarbage:
      fake_.send_unsolicited("\x13Z#?\x7f 9\r\x05");
      break;
    case FaultKind::SerialClosed:
      fake_.close_pty();
      break;
    case FaultKind::PositionMismatch:
      fake_.set_reported_position_offset(100);
      break;
    default:
      device_.inject(fault_.kind);
      break;
  }
  controller_.set_count_overruns(fault_.kind == FaultKind::OverrunStorm);
  injected_ = fault_.kind;
  injected_s_ = time.t_s;
  return true;
}

}  // namespace stencil::board::sim
