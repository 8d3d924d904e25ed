// The real LinuxCNC as the simulation's mill: see the header.
#include "board/sim/linuxcnc_wiring.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace stencil::board::sim {

bool parse_linuxcnc_sample(const std::string& line, LinuxcncSample& sample) {
  std::istringstream words(line);
  LinuxcncSample s{};
  double commands[3] = {};
  double spindle_rpm = 0.0;
  int machine_on = 0;
  int spindle_on = 0;
  if (!(words >> s.number >> s.position_mm[0] >> s.position_mm[1] >> s.position_mm[2] >> commands[0] >> commands[1] >>
        commands[2] >> spindle_rpm >> machine_on >> spindle_on)) {
    return false;
  }
  std::string rest;
  if (words >> rest) {
    return false;
  }
  s.machine_on = machine_on != 0;
  s.spindle_on = spindle_on != 0;
  sample = s;
  return true;
}

LinuxcncWiring::LinuxcncWiring(const SimJob& job)
    : samples_path_(job.linuxcnc->samples_path),
      frames_(true_frames(job.rig)),
      link_(clock_, job.linuxcnc->link),
      machined_{*job.part, job.stock, frames_, [this] { return static_cast<double>(clock_.now_ns()) / 1e9; }} {
  machined_.set_trace(job.trace);
  machined_.set_allowance(job.rig.facts.machine_standoff_mm);
  const std::string_view problem = hal::linuxcnc::check_linuxcnc_config(job.linuxcnc->link);
  if (!problem.empty()) {
    error_ = "the LinuxCNC mill: " + std::string(problem);
    return;
  }
  std::ifstream samples(samples_path_);
  if (!samples) {
    error_ = "the LinuxCNC mill's samples (halsampler's file, the ground truth): cannot read " + samples_path_;
  }
}

void LinuxcncWiring::arm() {
  std::ifstream samples(samples_path_);
  std::string line;
  skip_lines_ = 0;
  while (std::getline(samples, line)) {
    ++skip_lines_;
  }
  machined_.arm({0, 0, 0});  // LinuxCNC's home is machine 0: the same world point the frames put home at
}

void LinuxcncWiring::leave(SimResult& result, bool stop_confirmed, hal::MonotonicNs /*now_ns*/) {
  result.machine_stop_confirmed = stop_confirmed;
  std::ifstream samples(samples_path_);
  std::string line;
  for (std::uint64_t i = 0; i < skip_lines_ && std::getline(samples, line); ++i) {
  }
  bool have_last = false;
  LinuxcncSample last{};
  Eigen::Vector3d last_world = Eigen::Vector3d::Zero();
  while (std::getline(samples, line)) {
    LinuxcncSample sample{};
    if (!parse_linuxcnc_sample(line, sample)) {
      ++samples_lost_;  // "overrun", or a line cut short by the end of the file
      continue;
    }
    Eigen::Vector3d world;
    for (int i = 0; i < 3; ++i) {
      world[i] = frames_.home_world_mm[i] + frames_.machine_sign[static_cast<std::size_t>(i)] * sample.position_mm[i];
    }
    if (have_last) {
      if (sample.number != last.number + 1) {
        samples_lost_ += sample.number > last.number ? sample.number - last.number - 1 : 1;
      }
      if (world != last_world) {
        machined_.cut_recorded_leg(last_world, world);
      }
    }
    last = sample;
    last_world = world;
    have_last = true;
    ++samples_;
  }
  result.mill_spindle_on_after_stop = have_last && last.spindle_on;
  result.mill_drivers_on_after_stop = have_last && last.machine_on;
  result.mill_relay_dropped_power = false;  // LinuxCNC's machine off is its own: no relay of ours
  result.mill_on_after_relay = result.mill_spindle_on_after_stop || result.mill_drivers_on_after_stop;
}

}  // namespace stencil::board::sim
