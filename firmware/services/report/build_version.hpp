// What built a program: the source's version from git at build time (git describe --always --dirty
// --tags: a tag, or the commit, "-dirty" for uncommitted changes), the compiler and its flags. Every
// program's --version prints it.
#pragma once

#include <string>

namespace stencil::report {

[[nodiscard]] const char* source_version();
[[nodiscard]] const char* build_compiler();  // e.g. "GNU 12.2.0"
[[nodiscard]] const char* build_flags();

// --version's text: "PROGRAM VERSION" and a line with the compiler and flags.
[[nodiscard]] std::string version_text(const std::string& program);

}  // namespace stencil::report
