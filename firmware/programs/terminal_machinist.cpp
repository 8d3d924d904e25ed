#include "firmware/programs/terminal_machinist.hpp"

#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace stencil::app {
namespace {

// One line from stdin, waiting in slices of 100 ms with `idle` between: false at end of input or on
// an interrupt.
bool read_line(const std::atomic<bool>* interrupted, const std::function<void()>& idle, std::string& line) {
  line.clear();
  for (;;) {
    if (interrupted != nullptr && interrupted->load()) {
      return false;
    }
    pollfd input{STDIN_FILENO, POLLIN, 0};
    const int ready = ::poll(&input, 1, 100);
    idle();
    if (ready <= 0) {
      continue;
    }
    char byte = 0;
    const ssize_t got = ::read(STDIN_FILENO, &byte, 1);
    if (got <= 0) {
      return false;
    }
    if (byte == '\n') {
      return true;
    }
    if (line.size() < 64) {
      line += byte;
    }
  }
}

}  // namespace

void TerminalMachinist::say(const std::string& line) {
  std::printf("stencil-rig: %s\n", line.c_str());
  std::fflush(stdout);
}

bool TerminalMachinist::reading(int, const std::string& question, const std::function<void()>& idle, double& mm) {
  for (;;) {
    std::printf("stencil-rig: %s? ", question.c_str());
    std::fflush(stdout);
    std::string line;
    if (!read_line(interrupted_, idle, line)) {
      return false;
    }
    char* end = nullptr;
    mm = std::strtod(line.c_str(), &end);
    while (end != nullptr && (*end == ' ' || *end == '\r')) ++end;
    if (!line.empty() && end != nullptr && *end == '\0' && std::isfinite(mm)) {
      return true;
    }
    std::printf("stencil-rig: '%s' is not a reading: type the indicator's value in mm, e.g. -4.987\n", line.c_str());
  }
}

}  // namespace stencil::app
