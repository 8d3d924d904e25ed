// PeriodicRunner: how a board's run loop has its cycle run once per period, without knowing on
// what thread or with what privileges (the programs pass app::run_periodic's real-time thread; the
// tests pass the same thread unprivileged).
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "hal/clock.hpp"

namespace stencil::runtime {

// Runs cycle(now_ns, deadline_ns) once per period (on a real-time thread, where the host allows)
// until it returns false or `stop` is set; deadline_ns is the absolute start of the period. Blocks.
// False with `error` saying why when it refused to run (real-time privileges required and refused).
using PeriodicRunner = std::function<bool(hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
                                          const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle,
                                          std::string& error)>;

}  // namespace stencil::runtime
