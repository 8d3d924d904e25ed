// The safe state's reasons as data (control/safe_state.hpp): the fixed name each reason goes by in
// the journal, the report and the logs, and which reasons the device's own samples give (what a
// replay of the samples reproduces by itself). When the cycle enters each reason, and when a reset
// is taken, is the controller's decision: controller_tests has a case per trigger and per reset rule.
#include <cstdint>
#include <cstring>

#include "firmware/core/control/safe_state.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::control;

namespace {

struct NamedReason {
  SafeReason reason;
  const char* name;
  bool from_the_device;
};

// Every reason, in the enum's order: the names are part of the report's and the journal's format.
constexpr NamedReason kReasons[] = {
    {SafeReason::None, "none", false},
    {SafeReason::DeviceStale, "device_stale", true},
    {SafeReason::DeviceFault, "device_fault", true},
    {SafeReason::PoseNotFinite, "pose_not_finite", true},
    {SafeReason::PoseOutOfWorkspace, "pose_out_of_workspace", true},
    {SafeReason::PoseJump, "pose_jump", true},
    {SafeReason::MachineFault, "machine_fault", false},
    {SafeReason::OverrunStorm, "overrun_storm", false},
    {SafeReason::JournalFull, "journal_full", false},
    {SafeReason::JournalFailed, "journal_failed", false},
    {SafeReason::EngineFault, "engine_fault", false},
    {SafeReason::Stopped, "stopped", false},
};

}  // namespace

TEST_GROUP(SafeState){};

TEST(SafeState, EveryReasonHasItsOwnFixedName) {
  std::uint8_t expected_value = 0;
  for (const NamedReason& r : kReasons) {
    // The table walks the enum in order, so a reason added in the middle shows up here.
    LONGS_EQUAL(expected_value++, static_cast<std::uint8_t>(r.reason));
    STRCMP_EQUAL(r.name, safe_reason_name(r.reason));
  }
}

TEST(SafeState, AValueBeyondTheLastReasonIsNamedUnknown) {
  // The journal's readers take any value up to Stopped as a reason: Stopped must stay the last.
  const auto beyond = static_cast<SafeReason>(static_cast<std::uint8_t>(SafeReason::Stopped) + 1);
  STRCMP_EQUAL("unknown", safe_reason_name(beyond));
  STRCMP_EQUAL("unknown", safe_reason_name(static_cast<SafeReason>(255)));
}

TEST(SafeState, OnlyTheReasonsTheDevicesSamplesGiveAreDeviceReasons) {
  for (const NamedReason& r : kReasons) {
    CHECK_TEXT(is_device_reason(r.reason) == r.from_the_device, r.name);
  }
  static_assert(is_device_reason(SafeReason::PoseJump) && !is_device_reason(SafeReason::Stopped),
                "usable where a constant is needed");
}

TEST(SafeState, EveryReasonsByteIsAReasonAndTheNextOneIsNot) {
  for (const NamedReason& r : kReasons) {
    CHECK_TEXT(is_safe_reason_byte(static_cast<std::uint8_t>(r.reason)), r.name);
  }
  constexpr std::size_t count = sizeof(kReasons) / sizeof(kReasons[0]);
  CHECK_FALSE(is_safe_reason_byte(static_cast<std::uint8_t>(count)));
  CHECK_FALSE(is_safe_reason_byte(255));
}
