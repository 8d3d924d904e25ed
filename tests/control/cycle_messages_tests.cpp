// The messages in and out of the cycle (control/cycle_messages.hpp): the fixed names of command
// kinds, sources and outcomes that the journal, the report and the display use, which commands set
// a parameter, and the command ring's stamp of how many cycles had begun when a command was queued.
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/core/control/cycle_messages.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::control;

namespace {

// Every value below the count has a name of its own, and the count's value is "unknown": a kind
// added without its name, or without raising the count, fails here.
template <typename Enum, typename NameOf>
std::vector<std::string> names_below(std::uint8_t count, NameOf name_of) {
  std::vector<std::string> names;
  for (std::uint8_t value = 0; value < count; ++value) {
    names.emplace_back(name_of(static_cast<Enum>(value)));
    CHECK_TEXT(names.back() != "unknown", names.back().c_str());
    for (std::size_t i = 0; i + 1 < names.size(); ++i) {
      CHECK_TEXT(names[i] != names.back(), names.back().c_str());
    }
  }
  STRCMP_EQUAL("unknown", name_of(static_cast<Enum>(count)));
  return names;
}

}  // namespace

TEST_GROUP(CycleMessages){};

TEST(CycleMessages, EachCommandKindSourceAndOutcomeHasItsOwnNameAndTheCountsCoverThemAll) {
  const std::vector<std::string> kinds =
      names_below<CommandKind>(kCommandKindCount, [](CommandKind k) { return command_kind_name(k); });
  STRCMP_EQUAL("reset", kinds.front().c_str());
  STRCMP_EQUAL("journal_failed", kinds[2].c_str());
  STRCMP_EQUAL("resume", kinds[7].c_str());  // the kinds journalled before the wall's feel keep their numbers
  STRCMP_EQUAL("set_speed_limiting", kinds.back().c_str());
  const std::vector<std::string> sources =
      names_below<CommandSource>(kCommandSourceCount, [](CommandSource s) { return command_source_name(s); });
  STRCMP_EQUAL("cycle", sources.front().c_str());
  STRCMP_EQUAL("control", sources.back().c_str());
  const std::vector<std::string> outcomes =
      names_below<CommandOutcome>(kCommandOutcomeCount, [](CommandOutcome o) { return command_outcome_name(o); });
  STRCMP_EQUAL("done", outcomes.front().c_str());
  STRCMP_EQUAL("no_record_room", outcomes.back().c_str());
}

TEST(CycleMessages, TheResetAndParameterOutcomesAreNamedAsTheOperatorReadsThem) {
  names_below<ResetOutcome>(5, [](ResetOutcome o) { return reset_outcome_name(o); });
  STRCMP_EQUAL("device_far_from_tool", reset_outcome_name(ResetOutcome::DeviceFarFromTool));
  // A refused reset's word is the same in both vocabularies (the report prints either).
  STRCMP_EQUAL(reset_outcome_name(ResetOutcome::DeviceNotStill), command_outcome_name(CommandOutcome::DeviceNotStill));
  STRCMP_EQUAL(reset_outcome_name(ResetOutcome::DeviceNotReady), command_outcome_name(CommandOutcome::DeviceNotReady));
  names_below<ParameterOutcome>(4, [](ParameterOutcome o) { return parameter_outcome_name(o); });
  STRCMP_EQUAL("clamped", parameter_outcome_name(ParameterOutcome::Clamped));
}

TEST(CycleMessages, OnlyTheSetCommandsAreParametersAndEachNamesTheOneTheDisplayUses) {
  for (std::uint8_t value = 0; value < kCommandKindCount; ++value) {
    const auto kind = static_cast<CommandKind>(value);
    const std::string name = parameter_name(kind);
    const bool set = kind == CommandKind::SetCoupling || kind == CommandKind::SetForceLimit ||
                     kind == CommandKind::SetSpeedLimit || kind == CommandKind::SetDamping ||
                     kind == CommandKind::SetFriction || kind == CommandKind::SetSpeedLimiting;
    CHECK_TEXT(is_parameter(kind) == set, command_kind_name(kind));
    CHECK_TEXT((name != "none") == set, command_kind_name(kind));
    // Zero is a value only where it means "none" (no damping, no friction, the cap alone).
    const bool zero = kind == CommandKind::SetDamping || kind == CommandKind::SetFriction ||
                      kind == CommandKind::SetSpeedLimiting;
    CHECK_TEXT(zero_allowed(kind) == zero, command_kind_name(kind));
  }
  STRCMP_EQUAL("damping", parameter_name(CommandKind::SetDamping));
  STRCMP_EQUAL("friction", parameter_name(CommandKind::SetFriction));
  STRCMP_EQUAL("speed_limiting", parameter_name(CommandKind::SetSpeedLimiting));
  STRCMP_EQUAL("coupling", parameter_name(CommandKind::SetCoupling));
  STRCMP_EQUAL("force_limit", parameter_name(CommandKind::SetForceLimit));
  STRCMP_EQUAL("speed_limit", parameter_name(CommandKind::SetSpeedLimit));
}

TEST(CycleMessages, TheCommandRingStampsEachCommandWithTheCyclesBegunWhenItWasQueued) {
  CommandRing ring;
  // Whatever the producer wrote there is replaced: the stamp is the ring's.
  CHECK(ring.push({CommandKind::Stop, 0.0, CommandSource::Terminal, 999}));
  ring.begin_look(41);
  CHECK(ring.push({CommandKind::SetCoupling, 0.7, CommandSource::Display, 0}));
  Command out{};
  CHECK(ring.pop(out));
  CHECK(out.kind == CommandKind::Stop);
  CHECK(out.source == CommandSource::Terminal);
  LONGS_EQUAL(0, out.queued_after_cycle);
  CHECK(ring.pop(out));
  CHECK(out.kind == CommandKind::SetCoupling);
  DOUBLES_EQUAL(0.7, out.value, 0.0);
  LONGS_EQUAL(41, out.queued_after_cycle);
  CHECK_FALSE(ring.pop(out));
}

TEST(CycleMessages, AFullCommandRingRefusesTheNextCommandAndKeepsTheQueuedOnes) {
  CommandRing ring;
  for (std::size_t i = 0; i < CommandRing::capacity(); ++i) {
    CHECK(ring.push({CommandKind::Pause}));
  }
  CHECK_FALSE(ring.push({CommandKind::Stop}));
  LONGS_EQUAL(CommandRing::capacity(), ring.size());
  Command out{};
  CHECK(ring.pop(out));
  CHECK(out.kind == CommandKind::Pause);
  CHECK(ring.push({CommandKind::Stop}));  // room again
}

TEST(CycleMessages, TheRingStorageHandsTheCycleItsOwnRingsAndTheDisplaysIfAny) {
  static CycleRingStorage storage;  // seconds of journal records: not for the stack
  CommandRing display;
  const CycleRings without = storage.rings();
  POINTERS_EQUAL(&storage.commands, &without.commands);
  POINTERS_EQUAL(&storage.machine_events, &without.machine_events);
  POINTERS_EQUAL(&storage.machine, &without.machine);
  POINTERS_EQUAL(&storage.telemetry, &without.telemetry);
  POINTERS_EQUAL(&storage.journal, &without.journal);
  POINTERS_EQUAL(&storage.command_events, &without.command_events);
  POINTERS_EQUAL(nullptr, without.display_commands);
  POINTERS_EQUAL(&display, storage.rings(&display).display_commands);
}
