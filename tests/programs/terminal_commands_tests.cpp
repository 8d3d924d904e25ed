// The operator's lines at stencil-rig's terminal (firmware/programs/terminal_commands), read from
// standard input without waiting: 'start' before the cut, then 'stop', 'pause', 'resume' and 'reset'
// each on a line of its own (trailing spaces and a CR allowed), a line typed in pieces taken whole,
// anything else answered and skipped, the input's end seen. Standard input is a pipe here, put back
// after each test.
#include <optional>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "firmware/programs/terminal_commands.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using app::TerminalCommands;

TEST_GROUP(TerminalCommands) {
  int saved_stdin = -1;
  int saved_stderr = -1;
  int writer = -1;

  void setup() override {
    int ends[2] = {-1, -1};
    CHECK_EQUAL(0, pipe(ends));
    saved_stdin = dup(STDIN_FILENO);
    dup2(ends[0], STDIN_FILENO);
    close(ends[0]);
    writer = ends[1];
    // The answers to what is not understood go to stderr: kept out of the test's output.
    saved_stderr = dup(STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDERR_FILENO);
    close(null);
  }
  void teardown() override {
    if (writer >= 0) {
      close(writer);
    }
    dup2(saved_stdin, STDIN_FILENO);
    close(saved_stdin);
    dup2(saved_stderr, STDERR_FILENO);
    close(saved_stderr);
  }
  void type(const std::string& text) const { CHECK_EQUAL(static_cast<ssize_t>(text.size()), write(writer, text.data(), text.size())); }
  void close_input() {
    close(writer);
    writer = -1;
  }
};

TEST(TerminalCommands, NothingTypedIsNoWordAndNoCommand) {
  TerminalCommands terminal;
  CHECK(terminal.next_word() == TerminalCommands::Word::None);
  CHECK_FALSE(terminal.command_typed().has_value());
}

TEST(TerminalCommands, StartIsTheOnlyWordBeforeTheCut) {
  TerminalCommands terminal;
  type("go\nstart \r\n");
  CHECK(terminal.next_word() == TerminalCommands::Word::Start);
  type("begin\n");
  CHECK(terminal.next_word() == TerminalCommands::Word::None);
}

TEST(TerminalCommands, TheEndOfInputIsSeenBeforeTheCut) {
  TerminalCommands terminal;
  close_input();
  CHECK(terminal.next_word() == TerminalCommands::Word::Closed);
}

TEST(TerminalCommands, EachCommandIsItsOwnLine) {
  TerminalCommands terminal;
  type("stop\npause\nresume  \nreset\r\n");
  CHECK(terminal.command_typed() == control::CommandKind::Stop);
  CHECK(terminal.command_typed() == control::CommandKind::Pause);
  CHECK(terminal.command_typed() == control::CommandKind::Resume);
  CHECK(terminal.command_typed() == control::CommandKind::Reset);
  CHECK_FALSE(terminal.command_typed().has_value());
}

TEST(TerminalCommands, ALineTypedInPiecesIsTakenWhole) {
  TerminalCommands terminal;
  type("pa");
  CHECK_FALSE(terminal.command_typed().has_value());
  type("use\n");
  CHECK(terminal.command_typed() == control::CommandKind::Pause);
}

TEST(TerminalCommands, WhatIsNotACommandIsSkipped) {
  TerminalCommands terminal;
  type("STOP\nhalt\n\nstop please\nreset\n");
  CHECK(terminal.command_typed() == control::CommandKind::Reset);
}

TEST(TerminalCommands, AnOverlongLineIsDropped) {
  TerminalCommands terminal;
  type(std::string(2000, 'x'));
  CHECK_FALSE(terminal.command_typed().has_value());
  // Its end arrives with a command glued on: "x...xstop" was never a command line, so the
  // dropped beginning must not turn the rest into one.
  type("\nstop\n");
  CHECK(terminal.command_typed() == control::CommandKind::Stop);
}

TEST(TerminalCommands, AfterTheInputEndsWhatWasTypedIsStillTakenThenNothing) {
  TerminalCommands terminal;
  type("stop\n");
  close_input();
  CHECK(terminal.command_typed() == control::CommandKind::Stop);
  CHECK_FALSE(terminal.command_typed().has_value());
  CHECK(terminal.next_word() == TerminalCommands::Word::Closed);
}
