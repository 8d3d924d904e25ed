// What the host offers a real-time cycle: PREEMPT_RT, SCHED_FIFO, locked memory, /dev/cpu_dma_latency,
// isolated CPUs. Read once at start-up and printed, so a machinist knows what the loop will get.
#pragma once

#include <cstddef>
#include <string>

namespace stencil::app {

struct RtReadiness {
  bool preempt_rt = false;       // /sys/kernel/realtime says 1
  bool can_sched_fifo = false;   // this process may run a thread at SCHED_FIFO
  bool memlock_enough = false;   // RLIMIT_MEMLOCK covers the tables and stacks (or is unlimited)
  std::size_t memlock_limit_bytes = 0;
  bool dma_latency_available = false;  // /dev/cpu_dma_latency can be held at 0
  std::string isolated_cpus;     // /sys/devices/system/cpu/isolated ("" when none)
};

// Looks; changes nothing. `needed_lock_bytes`: what mlockall must be allowed to lock.
[[nodiscard]] RtReadiness check_rt_readiness(std::size_t needed_lock_bytes, int fifo_priority);

// One line per item, for stdout.
[[nodiscard]] std::string describe(const RtReadiness& readiness);

}  // namespace stencil::app
