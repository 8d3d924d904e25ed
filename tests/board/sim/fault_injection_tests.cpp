// The injectable faults' one table (board/sim/fault_injection): every name parses back to its kind,
// an unknown name is refused, and the lists the option's error and help are made of name every kind
// once, in order, with what a kind needs.
#include <string>

#include "board/sim/fault_injection.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::board::sim;

TEST_GROUP(FaultInjection){};

TEST(FaultInjection, EveryKindsNameParsesBackToIt) {
  for (int k = static_cast<int>(FaultKind::DeviceFrozen); k <= static_cast<int>(FaultKind::OverrunStorm); ++k) {
    const auto kind = static_cast<FaultKind>(k);
    FaultKind parsed = FaultKind::None;
    CHECK_TRUE(parse_fault_kind(fault_kind_name(kind), parsed));
    CHECK(parsed == kind);
  }
  STRCMP_EQUAL("cy545-garbled", fault_kind_name(FaultKind::Cy545Garbled));
  STRCMP_EQUAL("none", fault_kind_name(FaultKind::None));
}

TEST(FaultInjection, AnUnknownNameIsRefusedAndLeavesTheKind) {
  FaultKind kind = FaultKind::PoseNan;
  CHECK_FALSE(parse_fault_kind("device-melted", kind));
  CHECK_FALSE(parse_fault_kind("none", kind));  // nothing to inject is not a fault
  CHECK_FALSE(parse_fault_kind("Pose-Nan", kind));
  CHECK_FALSE(parse_fault_kind("", kind));
  CHECK(kind == FaultKind::PoseNan);
}

TEST(FaultInjection, ThePlainListNamesEveryKindInOrder) {
  STRCMP_EQUAL("device-frozen, pose-nan, pose-jump, device-fault, cy545-silent, cy545-garbled, serial-garbage, "
               "serial-closed, position-mismatch, can-bad-frames, overrun-storm",
               fault_kind_names(FaultKindList::Plain).c_str());
}

TEST(FaultInjection, TheSentenceEndsWithOrAndSaysWhatAKindNeeds) {
  const std::string sentence = fault_kind_names(FaultKindList::Sentence);
  STRCMP_CONTAINS("position-mismatch, can-bad-frames (needs --haptic-transport can) or overrun-storm", sentence.c_str());
  CHECK_EQUAL(0U, sentence.find("device-frozen, pose-nan"));
}
