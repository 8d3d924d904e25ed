// The faults the simulation can inject mid-job (stencil-sim --inject KIND@S), and their names: the
// one table of them, which the option's help and its error message are made from too.
#pragma once

#include <cstdint>
#include <string>

namespace stencil::board::sim {

// One fault injected mid-job (fast and paced runs): on the device's side, on the serial line, or in
// the CY545's answers.
enum class FaultKind : std::uint8_t {
  None,
  DeviceFrozen,      // the device stops: no sample, no heartbeat
  PoseNan,           // its samples carry NaN positions from then on
  PoseJump,          // one sample 100 mm off
  DeviceFault,       // it reports its own fault (amplifier, encoder)
  Cy545Silent,       // the CY545 stops answering (commands still run)
  Cy545Garbled,      // its answers arrive with every byte's top bit flipped
  SerialGarbage,     // bytes nobody asked for on the line
  SerialClosed,      // the cable is pulled: the pty's master closes
  PositionMismatch,  // the CY545 reports a position 100 steps off the one commanded
  CanBadFrames,      // over CAN, 20 ms of bad frames instead of the device's: a wrong DLC, halves whose counters disagree
  OverrunStorm,      // the cycle starts 1.5 periods late, every period from then on (a stalled host)
};
struct FaultInjection {
  FaultKind kind = FaultKind::None;
  double at_s = 0.0;  // simulated seconds from the start of the job
};

// "device-frozen", ... (the --inject names; "none" for None); parse_fault_kind gives false for an
// unknown name.
[[nodiscard]] const char* fault_kind_name(FaultKind kind);
[[nodiscard]] bool parse_fault_kind(const std::string& name, FaultKind& kind);

// Every kind's name but None's, in the enum's order: "device-frozen, pose-nan, ..., overrun-storm"
// (Plain, for an error message), or as a sentence for the help, with what a kind needs
// ("..., can-bad-frames (needs --haptic-transport can) or overrun-storm").
enum class FaultKindList : std::uint8_t { Plain, Sentence };
[[nodiscard]] std::string fault_kind_names(FaultKindList style);

}  // namespace stencil::board::sim
