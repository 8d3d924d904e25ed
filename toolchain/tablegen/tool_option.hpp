// Parses the machinist's tool notation: flat:d=D[,l=L], ball:d=D[,l=L], bull:d=D,r=RC[,l=L], and d=D,l=L holders.
#pragma once

#include <string>

#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::tablegen {

inline constexpr double kDefaultHolderDiameter_mm = 10.0;
inline constexpr double kDefaultHolderLength_mm = 20.0;

// The cutter from --tool (flute length defaults to 4 * D) with the holder from --holder (default
// d=10,l=20; empty text means the default). Throws InputError naming the option and the bad part.
[[nodiscard]] geometry::ToolSpec parse_tool(const std::string& tool_text, const std::string& holder_text);

}  // namespace stencil::tablegen
