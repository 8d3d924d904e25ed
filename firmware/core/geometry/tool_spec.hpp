// What a milling tool is: the cutter's kind and size, and the shank/holder above its flutes.
#pragma once

#include <cstdint>

namespace stencil::geometry {

enum class CutterKind : std::uint8_t {
  Flat,      // flat end mill: a cylinder with a flat bottom
  Ball,      // ball end mill: a cylinder ending in a hemisphere at the tip
  BullNose,  // bull-nose end mill: a flat bottom with a rounded corner of corner_radius_mm
};

// A tool as a machinist describes it, in millimetres. The tool frame has the tip (lowest point of
// the cutter) at the origin and the axis along +z, pointing up into the spindle.
struct ToolSpec {
  CutterKind kind;
  double diameter_mm;          // cutter diameter
  double flute_length_mm;      // length of the cutting part, from the tip up
  double corner_radius_mm;     // BullNose only; ignored otherwise
  double holder_diameter_mm;   // shank/holder above the flutes: at least the cutter diameter
  double holder_length_mm;     // shank/holder length above the flutes
};

}  // namespace stencil::geometry
