// What the table generator needs to know of the rig its tables are for, when no option says otherwise:
// the machine workspace (the part must fit it) and the largest backlash (a smaller allowance is warned
// about). The generator includes nothing from board/: the program is linked with the rig's board,
// which defines rig_defaults() from its facts (board/sherline_suzuki/tablegen_rig_defaults.cpp).
#pragma once

#include <array>

namespace stencil::tablegen {

struct RigDefaults {
  std::array<double, 3> workspace_mm;  // x y z: the box [0,X]x[0,Y]x[0,Z] (--workspace's default)
  double largest_backlash_mm;          // of any axis
};

// Defined by the board the program is linked with. Init-time, no I/O.
[[nodiscard]] RigDefaults rig_defaults();

}  // namespace stencil::tablegen
