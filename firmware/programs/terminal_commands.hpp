// The operator's lines at stencil-rig's terminal, read without waiting (from the records thread
// only): 'start' before the cut, 'reset' in a safe state. Anything else typed is answered with
// what is understood.
#pragma once

#include <string>

namespace stencil::app {

class TerminalCommands {
 public:
  enum class Word { None, Start, Closed };
  // Before the cut: whether 'start' was typed (anything else is answered), or the input closed.
  Word next_word();
  // True once a line says "reset".
  bool reset_typed();

 private:
  void read_pending();

  std::string pending_;
  bool closed_ = false;
};

}  // namespace stencil::app
