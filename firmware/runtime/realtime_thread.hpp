// The cycle's thread: SCHED_FIFO at a priority, optionally pinned to a CPU, memory locked, its stack
// prefaulted, woken by absolute clock_nanosleep on CLOCK_MONOTONIC once per period. Where the host
// refuses real-time privileges it says so once and runs anyway, unless they are required. And the
// same priority for another thread of ours (the machine thread, below the cycle).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "firmware/runtime/periodic_runner.hpp"
#include "hal/clock.hpp"

namespace stencil::app {

struct RealtimeOptions {
  int priority = 80;      // SCHED_FIFO
  int cpu = -1;           // pin to this CPU; -1: anywhere
  bool require = false;   // refuse to run without SCHED_FIFO and locked memory
};

// What the thread got.
struct RealtimeSetup {
  bool sched_fifo = false;
  bool pinned = false;
  bool memory_locked = false;
  bool dma_latency_held = false;  // /dev/cpu_dma_latency held at 0 while the loop ran
  std::string refused;  // non-empty: why it did not run (only with require)
};

// Holds /dev/cpu_dma_latency at 0 (no deep idle states) while it lives; held() says whether the
// host allowed it.
class CpuLatencyHold {
 public:
  CpuLatencyHold();
  ~CpuLatencyHold();
  CpuLatencyHold(const CpuLatencyHold&) = delete;
  CpuLatencyHold& operator=(const CpuLatencyHold&) = delete;
  [[nodiscard]] bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// Keeps the calling thread, and every thread it starts from now on, off `cpu` (the cycle's), so the
// cycle's CPU runs the cycle and nothing of ours that sits in the kernel when the cycle should wake.
// False (and nothing changed) when there is no other CPU or the host refuses.
bool keep_off_cpu(int cpu);

// What a thread asked for and what it got: it never claims a priority the kernel did not give it.
struct ThreadPriority {
  bool sched_fifo = false;  // the kernel says the thread runs SCHED_FIFO at `priority`
  int priority = 0;         // its SCHED_FIFO priority; 0 when it runs SCHED_OTHER
  std::string message;      // empty when it got what it asked; else one line: what was refused and why
};

// Init, on the thread itself: gives the calling thread SCHED_FIFO at `priority` (1 to 99), for a
// thread that must keep its deadlines beside the cycle but yield to it (the machine thread: the
// cycle's priority less a margin, above the records thread, which stays SCHED_OTHER). Where the
// host does not permit it (no CAP_SYS_NICE and RLIMIT_RTPRIO below the priority) or the priority is
// out of range, the thread runs SCHED_OTHER (put back there explicitly) and the message says so,
// naming `who`, the priority and the reason. What it returns is what pthread_getschedparam then says.
[[nodiscard]] ThreadPriority run_this_thread_fifo(int priority, const std::string& who);

// Runs `cycle(now_ns, deadline_ns)` once per period on a new thread until it returns false or `stop`
// is set; each call's deadline is the absolute start of its period. Blocks until the thread ends.
// `announce` gets one line per privilege missing (before the first cycle).
RealtimeSetup run_periodic(const RealtimeOptions& options, hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
                           const std::function<bool(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns)>& cycle,
                           const std::function<void(const std::string&)>& announce);

// run_periodic as the runtime's PeriodicRunner: its lines go to `announce`; a refusal (only with
// options.require) comes back as "--require-rt: <why>".
[[nodiscard]] runtime::PeriodicRunner realtime_runner(const RealtimeOptions& options,
                                                      std::function<void(const std::string&)> announce);

}  // namespace stencil::app
