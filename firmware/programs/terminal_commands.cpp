#include "firmware/programs/terminal_commands.hpp"

#include <cstdio>

#include <poll.h>
#include <unistd.h>

namespace stencil::app {

TerminalCommands::Word TerminalCommands::next_word() {
  read_pending();
  for (std::size_t end = pending_.find('\n'); end != std::string::npos; end = pending_.find('\n')) {
    std::string line = pending_.substr(0, end);
    pending_.erase(0, end + 1);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) {
      line.pop_back();
    }
    if (line == "start") {
      return Word::Start;
    }
    std::fprintf(stderr, "stencil-rig: '%s' is not 'start': type 'start' to turn the spindle on, or Ctrl-C\n", line.c_str());
  }
  return closed_ ? Word::Closed : Word::None;
}

std::optional<control::CommandKind> TerminalCommands::command_typed() {
  if (closed_ && pending_.empty()) {
    return std::nullopt;
  }
  read_pending();
  for (std::size_t end = pending_.find('\n'); end != std::string::npos; end = pending_.find('\n')) {
    std::string line = pending_.substr(0, end);
    pending_.erase(0, end + 1);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) {
      line.pop_back();
    }
    if (line == "stop") {
      return control::CommandKind::Stop;
    }
    if (line == "pause") {
      return control::CommandKind::Pause;
    }
    if (line == "resume") {
      return control::CommandKind::Resume;
    }
    if (line == "reset") {
      return control::CommandKind::Reset;
    }
    if (!line.empty()) {
      std::fprintf(stderr,
                   "stencil-rig: '%s' is not a command: type 'stop', 'pause', 'resume', 'reset' (in the safe state) "
                   "or Ctrl-C to end\n",
                   line.c_str());
    }
  }
  if (pending_.size() > 1024) {
    pending_.clear();  // a line that long is not a command
  }
  return std::nullopt;
}

void TerminalCommands::read_pending() {
  pollfd in{STDIN_FILENO, POLLIN, 0};
  while (!closed_ && poll(&in, 1, 0) > 0 && (in.revents & (POLLIN | POLLHUP)) != 0) {
    char bytes[256];
    const ssize_t n = ::read(STDIN_FILENO, bytes, sizeof bytes);
    if (n <= 0) {
      closed_ = true;  // end of input (not a terminal, or closed): nothing more to read
      break;
    }
    pending_.append(bytes, static_cast<std::size_t>(n));
  }
}

}  // namespace stencil::app
