// The machinist at stencil-rig's terminal during commissioning (firmware/programs/terminal_machinist):
// a dial indicator's reading typed as a number and Enter (trailing spaces and a CR allowed), anything
// else asked again, the end of input or an interrupt ending the wait, and the idle callback (the
// watchdog relay's heartbeat) called while waiting. Standard input is a pipe here, and standard output
// (the questions) a file, shown after a test only when it failed (CppUTest's own report of the
// failure goes there too); both are put back after each test.
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "firmware/programs/terminal_machinist.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using app::TerminalMachinist;

TEST_GROUP(TerminalMachinist) {
  int saved_stdin = -1;
  int saved_stdout = -1;
  int captured = -1;
  int writer = -1;
  int idles = 0;
  std::function<void()> idle = [this] { ++idles; };

  void setup() override {
    int ends[2] = {-1, -1};
    CHECK_EQUAL(0, pipe(ends));
    saved_stdin = dup(STDIN_FILENO);
    dup2(ends[0], STDIN_FILENO);
    close(ends[0]);
    writer = ends[1];
    std::fflush(stdout);
    saved_stdout = dup(STDOUT_FILENO);
    char name[] = "/tmp/terminal_machinist_tests_XXXXXX";
    captured = mkstemp(name);
    unlink(name);
    dup2(captured, STDOUT_FILENO);
  }
  void teardown() override {
    if (writer >= 0) {
      close(writer);
    }
    dup2(saved_stdin, STDIN_FILENO);
    close(saved_stdin);
    std::fflush(stdout);
    dup2(saved_stdout, STDOUT_FILENO);
    close(saved_stdout);
    if (UtestShell::getCurrent()->hasFailed()) {
      char text[4096];
      lseek(captured, 0, SEEK_SET);
      for (ssize_t n = read(captured, text, sizeof text); n > 0; n = read(captured, text, sizeof text)) {
        std::fwrite(text, 1, static_cast<std::size_t>(n), stdout);
      }
    }
    close(captured);
  }
  void type(const std::string& text) const { CHECK_EQUAL(static_cast<ssize_t>(text.size()), write(writer, text.data(), text.size())); }
  void close_input() {
    close(writer);
    writer = -1;
  }
};

TEST(TerminalMachinist, AReadingIsTheNumberTyped) {
  TerminalMachinist machinist(nullptr);
  type("-4.987 \r\n");
  double mm = 0.0;
  CHECK_TRUE(machinist.reading(0, "x at 10 mm", idle, mm));
  DOUBLES_EQUAL(-4.987, mm, 0.0);
  CHECK(idles >= 1);
}

TEST(TerminalMachinist, WhatIsNotANumberIsAskedAgain) {
  TerminalMachinist machinist(nullptr);
  type("about five\n\n5mm\nnan\n5.25\n");
  double mm = 0.0;
  CHECK_TRUE(machinist.reading(1, "y at 5 mm", idle, mm));
  DOUBLES_EQUAL(5.25, mm, 0.0);
}

TEST(TerminalMachinist, TheEndOfInputIsNoReading) {
  TerminalMachinist machinist(nullptr);
  type("not a number\n");
  close_input();
  double mm = 0.0;
  CHECK_FALSE(machinist.reading(2, "z at 3 mm", idle, mm));
}

TEST(TerminalMachinist, AnInterruptEndsTheWait) {
  const std::atomic<bool> interrupted{true};
  TerminalMachinist machinist(&interrupted);
  type("1.0\n");
  double mm = 0.0;
  CHECK_FALSE(machinist.reading(0, "x at 10 mm", idle, mm));
}

TEST(TerminalMachinist, WhileNothingIsTypedTheHeartbeatGoesOn) {
  std::atomic<bool> interrupted{false};
  TerminalMachinist machinist(&interrupted);
  // Nothing typed: each 100 ms slice calls idle; the third ends the wait.
  const std::function<void()> counting = [&] {
    if (++idles == 3) {
      interrupted = true;
    }
  };
  double mm = 0.0;
  CHECK_FALSE(machinist.reading(0, "x at 10 mm", counting, mm));
  CHECK_EQUAL(3, idles);
}
