// Whether a program's output files can be written, found out before the job rather than after it.
#pragma once

#include <string>

namespace stencil::app {

// True when `path` can be opened for writing; a file made only to find out is removed again, so a
// refused run leaves nothing behind. False with `error` naming the path.
[[nodiscard]] bool probe_writable(const std::string& path, std::string& error);

}  // namespace stencil::app
