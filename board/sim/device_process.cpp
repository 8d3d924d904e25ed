// The device's process: a millisecond loop, on the wall clock or in lockstep with the cycle, until
// its controller is gone; then on the wall clock until its watchdog has zeroed the force.
#include "board/sim/device_process.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <new>

#include <sched.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include "board/sim/sim_facts.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"

namespace stencil::board::sim {
namespace {

// kPeriodNs: sim_facts.hpp (the rig's device samples at the cycle's rate).

// The wall clock the device keeps once on its own: CLOCK_MONOTONIC, as the cycle's.
using hal::posix_clock::monotonic_now_ns;
using hal::posix_clock::sleep_until_monotonic_ns;

struct Child {
  stencil::sim::SimulatedHapticDevice& device;
  stencil::sim::OperatorHand& hand;
  const stencil::sim::OperatorScript& script;
  double duration_s;
  std::FILE* log;
  pid_t parent;
  DeviceProcessShared& shared;

  void publish() {
    const stencil::sim::DeviceOutput out = device.output();
    for (int i = 0; i < 3; ++i) {
      shared.force_n[i].store(out.force_n[i]);
    }
    shared.force_applied.store(out.force_applied);
  }

  // One device millisecond: the hand against the force the device drove, then a sample.
  void millisecond(double script_s, std::int64_t now_ns) {
    const stencil::sim::DeviceOutput out = device.output();
    hand.step(script.position_at(std::min(script_s, duration_s)),
              Eigen::Vector3d(out.force_n[0], out.force_n[1], out.force_n[2]));
    device.step(now_ns);
    publish();
  }

  // The controller is gone: on the wall clock, as the device would carry on, until the force is zero.
  [[noreturn]] void orphaned(double script_s, std::int64_t device_ns) {
    const std::int64_t gone = monotonic_now_ns();
    std::fprintf(log, "device: the controller's process is gone %.3f s into the job; force %s\n", script_s,
                 device.output().force_applied ? "still applied" : "already zero");
    std::fflush(log);
    for (std::int64_t next = gone;; next += kPeriodNs) {
      sleep_until_monotonic_ns(next);
      device_ns += kPeriodNs;
      millisecond(script_s, device_ns);
      const stencil::sim::DeviceOutput out = device.output();
      if (!out.force_applied) {
        std::fprintf(log, "device: force zero %.1f ms after the controller was gone (host watchdog trips: %llu)\n",
                     static_cast<double>(monotonic_now_ns() - gone) / 1e6, static_cast<unsigned long long>(out.watchdog_trips));
        std::fflush(log);
        _exit(0);
      }
      if (monotonic_now_ns() - gone > 1'000'000'000) {
        std::fprintf(log, "device: force still applied a second after the controller was gone\n");
        std::fflush(log);
        _exit(1);
      }
    }
  }

  [[noreturn]] void free_running() {
    std::int64_t first_command_ns = -1;
    for (std::int64_t next = monotonic_now_ns();; next += kPeriodNs) {
      sleep_until_monotonic_ns(next);
      const std::int64_t now = monotonic_now_ns();
      if (first_command_ns < 0 && device.output().commands_accepted > 0) {
        first_command_ns = now;
      }
      const double script_s = first_command_ns < 0 ? 0.0 : static_cast<double>(now - first_command_ns) / 1e9;
      if (getppid() != parent) {
        orphaned(script_s, now);
      }
      millisecond(script_s, now);
    }
  }

  [[noreturn]] void lockstep() {
    std::uint64_t done = 0;
    std::int64_t device_ns = 0;
    double script_s = 0.0;
    for (std::uint64_t spins = 0;; ++spins) {
      const std::uint64_t go = shared.go.load();
      if (go != done) {
        device_ns = shared.now_ns.load();
        script_s = shared.script_s.load();
        millisecond(script_s, device_ns);
        done = go;
        shared.done.store(done);
        spins = 0;
        continue;
      }
      if (spins % 64 == 0 && getppid() != parent) {
        orphaned(script_s, device_ns);
      }
      sched_yield();
    }
  }
};

}  // namespace

bool DeviceProcess::start(stencil::sim::SimulatedHapticDevice& device, stencil::sim::OperatorHand& hand,
                          const stencil::sim::OperatorScript& script, double duration_s, bool lockstep, std::FILE* log) {
  void* page = mmap(nullptr, sizeof(DeviceProcessShared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (page == MAP_FAILED) {
    return false;
  }
  shared_ = new (page) DeviceProcessShared;
  const pid_t parent = getpid();
  std::fflush(nullptr);  // nothing buffered is written twice
  child_ = fork();
  if (child_ < 0) {
    return false;
  }
  if (child_ == 0) {
    // Ctrl-C at the terminal reaches the whole group: the controller stops the job and then this
    // process; SIGTERM (from the controller) ends it. The controller's handlers are not ours.
    std::signal(SIGINT, SIG_IGN);
    std::signal(SIGTERM, SIG_DFL);
    if (!lockstep) {
      // As the rig's device would: ahead of everything but the cycle (best effort).
      sched_param param{};
      param.sched_priority = 70;
      static_cast<void>(sched_setscheduler(0, SCHED_FIFO, &param));
    }
    Child child{device, hand, script, duration_s, log, parent, *shared_};
    if (lockstep) {
      child.lockstep();
    }
    child.free_running();
  }
  return true;
}

bool DeviceProcess::step(std::int64_t now_ns, double script_s) {
  shared_->now_ns.store(now_ns);
  shared_->script_s.store(script_s);
  const std::uint64_t go = shared_->go.load() + 1;
  shared_->go.store(go);
  const std::int64_t give_up = monotonic_now_ns() + 1'000'000'000;
  for (std::uint64_t spins = 0; shared_->done.load() != go; ++spins) {
    if (spins % 64 == 0 && monotonic_now_ns() > give_up) {
      return false;
    }
    sched_yield();
  }
  return true;
}

bool DeviceProcess::force_off() const {
  return !shared_->force_applied.load() || force_n().norm() == 0.0;
}

Eigen::Vector3d DeviceProcess::force_n() const {
  return {shared_->force_n[0].load(), shared_->force_n[1].load(), shared_->force_n[2].load()};
}

void DeviceProcess::stop() {
  if (child_ > 0) {
    kill(child_, SIGTERM);
    int status = 0;
    while (waitpid(child_, &status, 0) < 0 && errno == EINTR) {
    }
    child_ = -1;
  }
  if (shared_ != nullptr) {
    shared_->~DeviceProcessShared();
    munmap(shared_, sizeof(DeviceProcessShared));
    shared_ = nullptr;
  }
}

}  // namespace stencil::board::sim
