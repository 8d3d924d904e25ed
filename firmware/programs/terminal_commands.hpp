// The operator's lines at stencil-rig's terminal, read without waiting (from the records thread
// only): 'start' before the cut; 'stop', 'pause', 'resume' and 'reset' (in a safe state) while it
// runs. Anything else typed is answered with what is understood.
#pragma once

#include <optional>
#include <string>

#include "firmware/core/control/cycle_messages.hpp"

namespace stencil::app {

class TerminalCommands {
 public:
  enum class Word { None, Start, Closed };
  // Before the cut: whether 'start' was typed (anything else is answered), or the input closed.
  Word next_word();
  // The next command typed ('stop', 'pause', 'resume', 'reset'), if a whole line says one.
  std::optional<control::CommandKind> command_typed();

 private:
  void read_pending();

  std::string pending_;
  bool closed_ = false;
};

}  // namespace stencil::app
