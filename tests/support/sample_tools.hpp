// Tools that the geometry tests run over: every cutter kind, under a wider holder and under a holder
// of the cutter's own diameter, including tools at the builder's limits.
#pragma once

#include <array>

#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::test {

struct NamedTool {
  const char* name;
  geometry::ToolSpec spec;
};

using geometry::CutterKind;

inline constexpr std::array<NamedTool, 8> kSampleTools = {{
    {"flat d3 under d10 holder", {CutterKind::Flat, 3.0, 12.0, 0.0, 10.0, 20.0}},
    {"flat d6 short, shank of own diameter", {CutterKind::Flat, 6.0, 3.0, 0.0, 6.0, 3.0}},
    {"ball d3 under d10 holder", {CutterKind::Ball, 3.0, 12.0, 0.0, 10.0, 20.0}},
    {"ball d4 hemisphere only, shank of own diameter", {CutterKind::Ball, 4.0, 2.0, 0.0, 4.0, 2.0}},
    {"ball d2 under slightly wider holder", {CutterKind::Ball, 2.0, 1.5, 0.0, 2.2, 1.0}},
    {"bull d6 r1 under d10 holder", {CutterKind::BullNose, 6.0, 8.0, 1.0, 10.0, 20.0}},
    {"bull d6 r3 (a ball), shank of own diameter", {CutterKind::BullNose, 6.0, 3.0, 3.0, 6.0, 5.0}},
    {"bull d2 r0.25 under d2.5 holder", {CutterKind::BullNose, 2.0, 3.0, 0.25, 2.5, 1.0}},
}};

}  // namespace stencil::test
