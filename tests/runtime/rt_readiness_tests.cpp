// What the host offers a real-time cycle (runtime/rt_readiness.hpp), read against the host itself:
// the locked-memory limit as the process has it (lowered here for a moment, so the rule is seen
// refusing), the kernel's and the CPUs' files, the probe leaving the calling thread's scheduling as
// it was, and the lines a machinist reads for each answer.
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstddef>
#include <fstream>
#include <string>

#include "firmware/runtime/rt_readiness.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

std::string first_line_of(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

TEST_GROUP(RtReadiness){};

TEST(RtReadiness, TheLockedMemoryLimitIsTheProcesssAndCoversWhatIsNeededOrNot) {
  rlimit saved{};
  CHECK(getrlimit(RLIMIT_MEMLOCK, &saved) == 0);
  rlimit low = saved;
  low.rlim_cur = 64 * 1024;  // below any hard limit a host sets; restored below
  CHECK(setrlimit(RLIMIT_MEMLOCK, &low) == 0);
  const app::RtReadiness small = app::check_rt_readiness(1024 * 1024, 1);
  const app::RtReadiness fits = app::check_rt_readiness(4096, 1);
  CHECK(setrlimit(RLIMIT_MEMLOCK, &saved) == 0);
  LONGS_EQUAL(64 * 1024, small.memlock_limit_bytes);
  // Root may lock beyond its limit; anyone else needs the limit to cover it.
  CHECK_EQUAL(geteuid() == 0, small.memlock_enough);
  CHECK(fits.memlock_enough);
}

TEST(RtReadiness, TheKernelAndTheIsolatedCpusAreReadFromTheirFiles) {
  const app::RtReadiness r = app::check_rt_readiness(0, 1);
  CHECK_EQUAL(first_line_of("/sys/kernel/realtime") == "1", r.preempt_rt);
  STRCMP_EQUAL(first_line_of("/sys/devices/system/cpu/isolated").c_str(), r.isolated_cpus.c_str());
  CHECK_EQUAL(access("/dev/cpu_dma_latency", W_OK) == 0, r.dma_latency_available);
}

TEST(RtReadiness, TheProbeLeavesTheCallingThreadsSchedulingAsItWas) {
  int policy_before = -1;
  sched_param before{};
  CHECK(pthread_getschedparam(pthread_self(), &policy_before, &before) == 0);
  static_cast<void>(app::check_rt_readiness(0, 10));
  int policy_after = -1;
  sched_param after{};
  CHECK(pthread_getschedparam(pthread_self(), &policy_after, &after) == 0);
  LONGS_EQUAL(policy_before, policy_after);
  LONGS_EQUAL(before.sched_priority, after.sched_priority);
}

TEST(RtReadiness, EachAnswerIsOneLineThatSaysWhatToDoWhenItIsNo) {
  const app::RtReadiness yes{true, true, true, 1 << 20, true, "2-3"};
  STRCMP_EQUAL(
      "  PREEMPT_RT kernel: yes\n"
      "  SCHED_FIFO: allowed\n"
      "  locked memory: enough\n"
      "  /dev/cpu_dma_latency: available (held at 0 while running)\n"
      "  isolated CPUs: 2-3\n",
      app::describe(yes).c_str());
  const app::RtReadiness no{};
  STRCMP_EQUAL(
      "  PREEMPT_RT kernel: no (wake-up latency will be the stock kernel's)\n"
      "  SCHED_FIFO: not allowed (run as root or grant CAP_SYS_NICE)\n"
      "  locked memory: RLIMIT_MEMLOCK too small for the tables (raise it: ulimit -l)\n"
      "  /dev/cpu_dma_latency: not available\n"
      "  isolated CPUs: none\n",
      app::describe(no).c_str());
}
