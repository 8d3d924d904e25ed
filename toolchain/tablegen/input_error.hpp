// The table generator's one error type: a message for the machinist, naming the file and the place.
#pragma once

#include <stdexcept>
#include <string>

namespace stencil::tablegen {

// Bad input (STL, options, output path): main() prints the message and exits with status 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace stencil::tablegen
