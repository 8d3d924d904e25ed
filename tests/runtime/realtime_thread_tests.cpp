// A thread asking for SCHED_FIFO (the machine thread, below the cycle) gets it or is told why not,
// and is never told it has a priority the kernel did not give it.
#include <cerrno>
#include <cstring>
#include <string>
#include <thread>

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "firmware/runtime/realtime_thread.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using stencil::app::run_this_thread_fifo;
using stencil::app::ThreadPriority;

namespace {

struct Policy {
  int policy = -1;
  int priority = -1;
};

Policy policy_of_this_thread() {
  Policy now;
  sched_param param{};
  if (pthread_getschedparam(pthread_self(), &now.policy, &param) == 0) {
    now.priority = param.sched_priority;
  }
  return now;
}

// On a thread of its own, so the test runner's thread keeps its policy.
void on_a_new_thread(int priority, ThreadPriority& got, Policy& after) {
  std::thread thread([&] {
    got = run_this_thread_fifo(priority, "the test's thread");
    after = policy_of_this_thread();
  });
  thread.join();
}

}  // namespace

// The threads allocate beside the test's, which CppUTest's leak detector does not take.
TEST_GROUP(RealtimeThread) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

// Root (or CAP_SYS_NICE, or RLIMIT_RTPRIO) gets it; anyone else is told why not. Either way what
// comes back is what the kernel says of the thread.
TEST(RealtimeThread, AThreadAskingForFifoGetsItAtThatPriorityOrIsToldWhyNot) {
  ThreadPriority got;
  Policy after;
  on_a_new_thread(10, got, after);
  if (got.sched_fifo) {
    LONGS_EQUAL(SCHED_FIFO, after.policy);
    LONGS_EQUAL(10, after.priority);
    LONGS_EQUAL(10, got.priority);
    STRCMP_EQUAL("", got.message.c_str());
  } else {
    LONGS_EQUAL(SCHED_OTHER, after.policy);
    LONGS_EQUAL(0, got.priority);
    STRCMP_CONTAINS("the test's thread: SCHED_FIFO at priority 10 was refused", got.message.c_str());
    STRCMP_CONTAINS("it runs at normal priority (SCHED_OTHER)", got.message.c_str());
  }
}

TEST(RealtimeThread, APriorityOutOfRangeIsRefusedNamingTheRangeAndTheThreadStaysNormal) {
  for (const int priority : {0, 100, -3}) {
    ThreadPriority got;
    Policy after;
    on_a_new_thread(priority, got, after);
    CHECK_FALSE(got.sched_fifo);
    LONGS_EQUAL(0, got.priority);
    LONGS_EQUAL(SCHED_OTHER, after.policy);
    STRCMP_CONTAINS(("SCHED_FIFO at priority " + std::to_string(priority) + " was refused (expected a priority from 1 to 99)")
                        .c_str(),
                    got.message.c_str());
  }
}

// Without the privilege (a child process that gave up root and has RLIMIT_RTPRIO 0): refused as not
// permitted, and the thread runs SCHED_OTHER, put back there even from the FIFO it inherited.
TEST(RealtimeThread, WithoutThePrivilegeTheThreadFallsBackToNormalPriorityAndSaysWhy) {
  int pipe_ends[2];
  CHECK(pipe(pipe_ends) == 0);
  const pid_t child = fork();
  CHECK(child >= 0);
  if (child == 0) {
    ::close(pipe_ends[0]);
    // Start from SCHED_FIFO where the host allows it, as a thread made by a real-time thread would.
    sched_param fifo{};
    fifo.sched_priority = 5;
    static_cast<void>(pthread_setschedparam(pthread_self(), SCHED_FIFO, &fifo));
    const rlimit none{0, 0};
    static_cast<void>(setrlimit(RLIMIT_RTPRIO, &none));
    if (getuid() == 0 && setuid(65534) != 0) {
      _exit(2);
    }
    const ThreadPriority got = run_this_thread_fifo(20, "the machine thread");
    const Policy after = policy_of_this_thread();
    const std::string report = std::string(got.sched_fifo ? "fifo" : "other") + "|" +
                               std::to_string(after.policy == SCHED_OTHER) + "|" + got.message;
    static_cast<void>(write(pipe_ends[1], report.data(), report.size()));
    _exit(0);
  }
  ::close(pipe_ends[1]);
  std::string report;
  char buffer[512];
  ssize_t n = 0;
  while ((n = read(pipe_ends[0], buffer, sizeof buffer)) > 0) {
    report.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(pipe_ends[0]);
  int status = 0;
  CHECK(waitpid(child, &status, 0) == child);
  CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  STRCMP_CONTAINS("other|1|the machine thread: SCHED_FIFO at priority 20 was refused (not permitted", report.c_str());
  STRCMP_CONTAINS("it runs at normal priority (SCHED_OTHER)", report.c_str());
}
