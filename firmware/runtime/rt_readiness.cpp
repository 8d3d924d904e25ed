// Reading the host's real-time readiness.
#include "firmware/runtime/rt_readiness.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <thread>

namespace stencil::app {
namespace {

std::string first_line(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

RtReadiness check_rt_readiness(std::size_t needed_lock_bytes, int fifo_priority) {
  RtReadiness r;
  r.preempt_rt = first_line("/sys/kernel/realtime") == "1";
  // Try SCHED_FIFO on a short-lived thread of our own, so this thread's policy is not touched.
  std::thread probe([&] {
    sched_param param{};
    param.sched_priority = fifo_priority;
    r.can_sched_fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  });
  probe.join();
  rlimit limit{};
  if (getrlimit(RLIMIT_MEMLOCK, &limit) == 0) {
    r.memlock_limit_bytes = limit.rlim_cur == RLIM_INFINITY ? static_cast<std::size_t>(-1) : limit.rlim_cur;
    r.memlock_enough = limit.rlim_cur == RLIM_INFINITY || limit.rlim_cur >= needed_lock_bytes || geteuid() == 0;
  }
  const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  r.dma_latency_available = fd >= 0;
  if (fd >= 0) {
    ::close(fd);
  }
  r.isolated_cpus = first_line("/sys/devices/system/cpu/isolated");
  return r;
}

std::string describe(const RtReadiness& r) {
  std::string out;
  out += std::string("  PREEMPT_RT kernel: ") + (r.preempt_rt ? "yes" : "no (wake-up latency will be the stock kernel's)") + "\n";
  out += std::string("  SCHED_FIFO: ") + (r.can_sched_fifo ? "allowed" : "not allowed (run as root or grant CAP_SYS_NICE)") + "\n";
  out += std::string("  locked memory: ") +
         (r.memlock_enough ? "enough" : "RLIMIT_MEMLOCK too small for the tables (raise it: ulimit -l)") + "\n";
  out += std::string("  /dev/cpu_dma_latency: ") + (r.dma_latency_available ? "available (held at 0 while running)" : "not available") + "\n";
  out += "  isolated CPUs: " + (r.isolated_cpus.empty() ? std::string("none") : r.isolated_cpus) + "\n";
  return out;
}

}  // namespace stencil::app
