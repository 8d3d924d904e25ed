// The table generator's defaults on this rig: its workspace and its largest backlash (rig_facts.hpp).
#include "board/sherline_suzuki/rig_facts.hpp"
#include "toolchain/tablegen/rig_defaults.hpp"

namespace stencil::tablegen {

RigDefaults rig_defaults() {
  namespace rig = board::sherline_suzuki;
  return {rig::kRig.workspace_mm, rig::largest_backlash_mm()};
}

}  // namespace stencil::tablegen
