// A job's parts for the runtime's tests: the hex prism's tables, a scripted haptic device held where
// the tool is at home (above the prism: free air), a spy mill that does at once what it is told, and
// a virtual clock; and a hook that writes down when it was called.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/tables/table_loader.hpp"
#include "firmware/runtime/cycle_config.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "firmware/runtime/job_parts.hpp"
#include "sim/clock/virtual_clock.hpp"
#include "tests/fakes/fake_haptic_device.hpp"
#include "tests/fakes/spy_machine_link.hpp"
#include "tests/support/sample_tables.hpp"

#include <CppUTest/TestHarness.h>

namespace stencil::test {

inline constexpr hal::MonotonicNs kUpdateNs = 1'000'000'000 / 30;

struct JobBench {
  tablegen::TableBytes bytes = make_table(default_part(), default_job_options(2));
  tables::PartTables part{};
  FakeHapticDevice device;
  SpyMachineLink link;
  sim::VirtualClock clock{0};
  const Eigen::Vector3d home_world_mm{25.0, 12.5, 20.0};

  JobBench() {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    device.hold_at(10.0 * home_world_mm.x(), 10.0 * home_world_mm.y(), 10.0 * home_world_mm.z());
  }

  [[nodiscard]] runtime::JobParts parts(bool count_overruns = false) {
    runtime::JobParts parts;
    parts.part = &part;
    parts.device = &device;
    parts.machine = &link;
    parts.machine_clock = &clock;
    const motion::MachineFrames frames{10.0, Eigen::Vector3d::Zero(), home_world_mm, {-1, -1, -1}, 640.0};
    // A device 500 x 250 x 250 mm reaching 25 mm past it, 5 N and 200 N mm, a 1 ms cycle, 1 mm/s.
    parts.controller =
        runtime::controller_config({frames, Eigen::Vector3d(500.0, 250.0, 250.0), 25.0, 5.0, 200.0, 1e-3, 1.0, 0.0, count_overruns});
    parts.planner = {{1.4, 1000.0, 640.0}, 1.0 / 30.0, {80, 32, 80}};
    parts.update_ns = kUpdateNs;
    parts.shut_down_bound_ns = 3 * kUpdateNs;
    parts.stock = {{0.0, 0.0, 0.0}, {50.0, 25.0, 10.0}};
    return parts;
  }
};

// Writes down each call: "C" before a cycle, "c" after it, "M" after a machine update; ends the run
// before cycle `last_cycle` + 1 (counting from 1), and says the job is done from `done_at_s` on.
class DiaryHook final : public runtime::JobHooks {
 public:
  std::string diary;
  std::vector<double> seconds_asked;  // job_done's t_s
  std::uint64_t last_cycle = std::numeric_limits<std::uint64_t>::max();
  double done_at_s = 1e300;
  hal::MonotonicNs late_ns = 0;
  std::uint64_t telemetry_frames = 0;
  std::uint64_t request_calls = 0;

  bool before_cycle(const runtime::CycleTime&) override {
    if (cycles_ == last_cycle) {
      return false;
    }
    diary += 'C';
    return true;
  }
  void after_cycle(const runtime::CycleTime&, control::CycleStatus) override {
    ++cycles_;
    diary += 'c';
  }
  [[nodiscard]] hal::MonotonicNs lateness_ns() const override { return late_ns; }
  bool job_done(double t_s, bool) override {
    seconds_asked.push_back(t_s);
    return t_s >= done_at_s;
  }
  void after_machine_update() override { diary += 'M'; }
  void on_telemetry(const control::Telemetry&) override { ++telemetry_frames; }
  void forward_requests(control::CommandRing&) override { ++request_calls; }

 private:
  std::uint64_t cycles_ = 0;
};

// From cycle `at` on (counting from 1), the device reports its own fault: a hook on the cycle's
// thread (in virtual time, in the cycle's place).
class DeviceFaultAt final : public runtime::JobHooks {
 public:
  DeviceFaultAt(FakeHapticDevice& device, std::uint64_t at) : device_(device), at_(at) {}
  bool before_cycle(const runtime::CycleTime&) override {
    if (++cycle_ == at_) {
      device_.give(hal::ReadStatus::Fault, hal::HapticFault::DeviceHeartbeatLost);
    }
    return true;
  }

 private:
  FakeHapticDevice& device_;
  std::uint64_t at_;
  std::uint64_t cycle_ = 0;
};

}  // namespace stencil::test
