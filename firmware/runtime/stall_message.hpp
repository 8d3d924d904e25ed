// What a stall of the mill says: where the virtual tool and the mill were and what the planner tried,
// so that a stall that does happen can be reproduced and explained.
#pragma once

#include <string>

#include "firmware/core/control/machine_side.hpp"

namespace stencil::runtime {

[[nodiscard]] std::string stall_message(const control::MachineSide::Stall& stall);

}  // namespace stencil::runtime
