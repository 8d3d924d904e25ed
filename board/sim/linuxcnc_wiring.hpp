// The simulation's machine when it is the real LinuxCNC (sim/linuxcnc_mill, started beside the job):
// the LinuxCNC link on the wall clock, and the ground truth read back from halsampler's file, every
// servo period's joint positions (not a 30 Hz poll): each millisecond's straight step from one sample
// to the next is cut into the machined part, its gouge measured against the part's triangles.
#pragma once

#include <cstdint>
#include <string>

#include "board/sim/sim_job.hpp"
#include "board/sim/sim_machine.hpp"
#include "hal/linuxcnc/linuxcnc_link.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/mill/machined_part.hpp"

namespace stencil::board::sim {

// One line of halsampler's file as sim/linuxcnc_mill's sampler writes it: the sample's number, the
// X Y Z motor positions (machine mm), the X Y Z commands, the spindle's speed command, machine on,
// spindle on. False for any other line ("overrun", a torn last line).
struct LinuxcncSample {
  std::uint64_t number;
  double position_mm[3];
  bool machine_on;
  bool spindle_on;
};
[[nodiscard]] bool parse_linuxcnc_sample(const std::string& line, LinuxcncSample& sample);

class LinuxcncWiring final : public SimMachine {
 public:
  explicit LinuxcncWiring(const SimJob& job);

  [[nodiscard]] const std::string& error() const override { return error_; }
  [[nodiscard]] hal::linuxcnc::LinuxcncLink& link() override { return link_; }
  [[nodiscard]] const char* link_error() const override { return link_.last_error(); }
  [[nodiscard]] hal::Clock& clock() override { return clock_; }
  [[nodiscard]] stencil::sim::MachinedPart& machined() override { return machined_; }
  [[nodiscard]] const stencil::sim::MachinedPart& machined() const override { return machined_; }
  // Homed: the samples from here on are the job's (the file's lines so far are skipped).
  void arm() override;
  // Reads the samples since arm() into the machined part; what the last sample says of the machine
  // and the spindle is what the machinist finds (LinuxCNC has no watchdog relay of ours).
  void leave(SimResult& result, bool stop_confirmed, hal::MonotonicNs now_ns) override;

  // What the ground truth held: samples read, lost ones (halsampler's overruns and gaps in the numbers).
  [[nodiscard]] std::uint64_t samples() const { return samples_; }
  [[nodiscard]] std::uint64_t samples_lost() const { return samples_lost_; }

 private:
  std::string samples_path_;
  motion::MachineFrames frames_;
  hal::posix_clock::MonotonicClock clock_;
  hal::linuxcnc::LinuxcncLink link_;
  stencil::sim::MachinedPart machined_;
  std::string error_;
  std::uint64_t skip_lines_ = 0;
  std::uint64_t samples_ = 0;
  std::uint64_t samples_lost_ = 0;
};

}  // namespace stencil::board::sim
