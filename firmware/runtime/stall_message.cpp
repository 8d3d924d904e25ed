// The stall's message.
#include "firmware/runtime/stall_message.hpp"

#include <cstdio>

namespace stencil::runtime {

std::string stall_message(const control::MachineSide::Stall& stall) {
  char text[512];
  const motion::PlanSearch& s = stall.search;
  std::snprintf(text, sizeof text,
                "the mill found no legal way along the virtual tool's path for 3 s (stalled): the virtual tool at "
                "(%.5f, %.5f, %.5f) mm, the mill at (%.5f, %.5f, %.5f) mm, its next path point (%.5f, %.5f, %.5f) mm; "
                "tried %d path points, %d grid corners (%d legal), %d staircases, %d one-axis legs",
                stall.virtual_tip_mm.x(), stall.virtual_tip_mm.y(), stall.virtual_tip_mm.z(), stall.mill_tip_mm.x(),
                stall.mill_tip_mm.y(), stall.mill_tip_mm.z(), s.next_point_mm.x(), s.next_point_mm.y(),
                s.next_point_mm.z(), s.candidates, s.corners, s.legal_corners, s.staircases, s.legs);
  return text;
}

}  // namespace stencil::runtime
