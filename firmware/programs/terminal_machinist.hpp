// The machinist at stencil-rig's terminal, for commissioning: each question on stdout, each dial
// indicator reading typed as a number and Enter on stdin. While waiting, the link's heartbeat goes on
// (the idle callback every 100 ms), so the watchdog relay keeps the drivers powered and the axes held.
#pragma once

#include <atomic>

#include "board/sherline_suzuki/commissioning.hpp"

namespace stencil::app {

class TerminalMachinist final : public board::sherline_suzuki::CommissioningOperator {
 public:
  explicit TerminalMachinist(const std::atomic<bool>* interrupted) : interrupted_(interrupted) {}

  void say(const std::string& line) override;
  // A line that is not a number is asked again; end of input or an interrupt: false.
  bool reading(int axis, const std::string& question, const std::function<void()>& idle, double& mm) override;

 private:
  const std::atomic<bool>* interrupted_;
};

}  // namespace stencil::app
