// The cycle's real-time thread.
#include "firmware/runtime/realtime_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>
#include <utility>

#include "hal/posix_clock/monotonic_clock.hpp"

namespace stencil::app {
namespace {

using hal::posix_clock::monotonic_now_ns;
using hal::posix_clock::sleep_until_monotonic_ns;

// Touches the pages the cycle's stack will use, so the first deep call does not fault them in.
__attribute__((noinline)) void prefault_stack() {
  volatile unsigned char stack[256 * 1024];
  for (std::size_t i = 0; i < sizeof stack; i += 4096) {
    stack[i] = 0;
  }
}

}  // namespace

CpuLatencyHold::CpuLatencyHold() {
  fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd_ >= 0) {
    const std::int32_t zero = 0;
    if (::write(fd_, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
      ::close(fd_);
      fd_ = -1;
    }
  }
}

CpuLatencyHold::~CpuLatencyHold() {
  if (fd_ >= 0) {
    ::close(fd_);  // the kernel drops the request with the last open file
  }
}

bool keep_off_cpu(int cpu) {
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (sched_getaffinity(0, sizeof cpus, &cpus) != 0 || cpu < 0 || cpu >= CPU_SETSIZE) {
    return false;
  }
  CPU_CLR(static_cast<std::size_t>(cpu), &cpus);
  return CPU_COUNT(&cpus) > 0 && sched_setaffinity(0, sizeof cpus, &cpus) == 0;
}

ThreadPriority run_this_thread_fifo(int priority, const std::string& who) {
  const std::string asked = who + ": SCHED_FIFO at priority " + std::to_string(priority);
  int error_number = EINVAL;
  if (priority >= sched_get_priority_min(SCHED_FIFO) && priority <= sched_get_priority_max(SCHED_FIFO)) {
    sched_param param{};
    param.sched_priority = priority;
    error_number = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  }
  ThreadPriority got;
  if (error_number != 0) {
    // Refused: explicitly back to (or left at) the normal policy, whatever the thread inherited.
    sched_param normal{};
    static_cast<void>(pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal));
    got.message = asked + " was refused (" +
                  (error_number == EPERM ? std::string("not permitted: run as root or grant CAP_SYS_NICE, or raise RLIMIT_RTPRIO")
                   : error_number == EINVAL ? "expected a priority from " + std::to_string(sched_get_priority_min(SCHED_FIFO)) +
                                                  " to " + std::to_string(sched_get_priority_max(SCHED_FIFO))
                                            : std::string(std::strerror(error_number))) +
                  "): it runs at normal priority (SCHED_OTHER)";
  }
  // What the kernel says now, not what was asked.
  int policy = SCHED_OTHER;
  sched_param now{};
  if (pthread_getschedparam(pthread_self(), &policy, &now) == 0 && policy == SCHED_FIFO) {
    got.sched_fifo = true;
    got.priority = now.sched_priority;
  }
  if (error_number == 0 && (!got.sched_fifo || got.priority != priority)) {
    got.message = asked + " was taken but the thread runs " +
                  (got.sched_fifo ? "SCHED_FIFO at priority " + std::to_string(got.priority) : std::string("another policy"));
  }
  return got;
}

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
    // Held while the loop runs: the CPUs stay out of deep idle states, whose exit on a wake-up can
    // take longer than the period (cyclictest holds it too, so the two are measured alike).
    CpuLatencyHold latency_hold;
    setup.dma_latency_held = latency_hold.held();
    if (!setup.dma_latency_held) {
      announce("/dev/cpu_dma_latency could not be held at 0: the CPUs may sleep deeply between cycles");
    }
    hal::MonotonicNs deadline = (monotonic_now_ns() / period_ns + 1) * period_ns;
    while (!stop.load(std::memory_order_relaxed)) {
      sleep_until_monotonic_ns(deadline);
      if (!cycle(monotonic_now_ns(), deadline)) {
        break;
      }
      deadline += period_ns;
      // Periods that went by whole while the cycle was late (a stall of the host) are skipped
      // rather than run back to back, each of which would overrun in turn; the period now under
      // way runs at once, late. The controller counts the periods skipped.
      const hal::MonotonicNs now = monotonic_now_ns();
      if (now >= deadline + period_ns) {
        deadline += ((now - deadline) / period_ns) * period_ns;
      }
    }
  });
  thread.join();
  return setup;
}

runtime::PeriodicRunner realtime_runner(const RealtimeOptions& options, std::function<void(const std::string&)> announce) {
  return [options, announce = std::move(announce)](hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
                                                   const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle,
                                                   std::string& refused) {
    const RealtimeSetup setup = run_periodic(options, period_ns, stop, cycle, announce);
    refused = setup.refused.empty() ? "" : "--require-rt: " + setup.refused;
    return setup.refused.empty();
  };
}

}  // namespace stencil::app
