// The cycle's real-time thread.
#include "firmware/app/realtime_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <cstring>
#include <thread>

namespace stencil::app {
namespace {

hal::MonotonicNs monotonic_now() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<hal::MonotonicNs>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void sleep_until(hal::MonotonicNs deadline) {
  const timespec at{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
  }
}

// Touches the pages the cycle's stack will use, so the first deep call does not fault them in.
__attribute__((noinline)) void prefault_stack() {
  volatile unsigned char stack[256 * 1024];
  for (std::size_t i = 0; i < sizeof stack; i += 4096) {
    stack[i] = 0;
  }
}

}  // namespace

RealtimeSetup run_periodic(const RealtimeOptions& options, hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
                           const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle,
                           const std::function<void(const std::string&)>& announce) {
  RealtimeSetup setup;
  setup.memory_locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  if (!setup.memory_locked) {
    announce(std::string("mlockall: ") + std::strerror(errno) + " (pages may fault in the cycle)");
  }
  std::thread thread([&] {
    sched_param param{};
    param.sched_priority = options.priority;
    setup.sched_fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
    if (options.cpu >= 0) {
      cpu_set_t cpus;
      CPU_ZERO(&cpus);
      CPU_SET(static_cast<std::size_t>(options.cpu), &cpus);
      setup.pinned = pthread_setaffinity_np(pthread_self(), sizeof cpus, &cpus) == 0;
    }
    if (options.require && (!setup.sched_fifo || !setup.memory_locked)) {
      setup.refused = !setup.sched_fifo ? "SCHED_FIFO was refused (run as root or grant CAP_SYS_NICE)"
                                        : "mlockall was refused (raise RLIMIT_MEMLOCK)";
      return;
    }
    if (!setup.sched_fifo) {
      announce("SCHED_FIFO was refused: the cycle runs at normal priority");
    }
    if (options.cpu >= 0 && !setup.pinned) {
      announce("pinning to CPU " + std::to_string(options.cpu) + " was refused");
    }
    prefault_stack();
    hal::MonotonicNs deadline = (monotonic_now() / period_ns + 1) * period_ns;
    while (!stop.load(std::memory_order_relaxed)) {
      sleep_until(deadline);
      if (!cycle(monotonic_now(), deadline)) {
        break;
      }
      deadline += period_ns;
      // Woken so late that the next period is already gone (a stall of the host, not of the cycle):
      // skip to the next period boundary rather than run a burst of late cycles back to back, each
      // of which would overrun in turn. The controller counts the periods skipped.
      const hal::MonotonicNs now = monotonic_now();
      if (now >= deadline) {
        deadline += ((now - deadline) / period_ns + 1) * period_ns;
      }
    }
  });
  thread.join();
  return setup;
}

}  // namespace stencil::app
