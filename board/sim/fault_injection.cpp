// The injectable faults' names: one table for the option's parsing, the report and the help.
#include "board/sim/fault_injection.hpp"

#include <iterator>

namespace stencil::board::sim {
namespace {

struct FaultKindEntry {
  FaultKind kind;
  const char* name;
  const char* needs;  // what the job must have for it (the help says so), or null
};

constexpr FaultKindEntry kFaultKinds[] = {
    {FaultKind::DeviceFrozen, "device-frozen", nullptr},
    {FaultKind::PoseNan, "pose-nan", nullptr},
    {FaultKind::PoseJump, "pose-jump", nullptr},
    {FaultKind::DeviceFault, "device-fault", nullptr},
    {FaultKind::Cy545Silent, "cy545-silent", nullptr},
    {FaultKind::Cy545Garbled, "cy545-garbled", nullptr},
    {FaultKind::SerialGarbage, "serial-garbage", nullptr},
    {FaultKind::SerialClosed, "serial-closed", nullptr},
    {FaultKind::PositionMismatch, "position-mismatch", nullptr},
    {FaultKind::CanBadFrames, "can-bad-frames", "--haptic-transport can"},
    {FaultKind::OverrunStorm, "overrun-storm", nullptr},
};

}  // namespace

const char* fault_kind_name(FaultKind kind) {
  for (const FaultKindEntry& entry : kFaultKinds) {
    if (entry.kind == kind) {
      return entry.name;
    }
  }
  return "none";
}

bool parse_fault_kind(const std::string& name, FaultKind& kind) {
  for (const FaultKindEntry& entry : kFaultKinds) {
    if (name == entry.name) {
      kind = entry.kind;
      return true;
    }
  }
  return false;
}

std::string fault_kind_names(FaultKindList style) {
  std::string names;
  constexpr std::size_t kCount = std::size(kFaultKinds);
  for (std::size_t i = 0; i < kCount; ++i) {
    if (i > 0) {
      names += style == FaultKindList::Sentence && i + 1 == kCount ? " or " : ", ";
    }
    names += kFaultKinds[i].name;
    if (style == FaultKindList::Sentence && kFaultKinds[i].needs != nullptr) {
      names += std::string(" (needs ") + kFaultKinds[i].needs + ")";
    }
  }
  return names;
}

}  // namespace stencil::board::sim
