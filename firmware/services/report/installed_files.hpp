// Where a program finds the files that ship beside it (the display's page, the sample parts): under
// <prefix>/share/stencil when it is installed in <prefix>/bin, else in its build tree (build/bin's
// parent holds hmi/ and parts/). Nothing is looked up in the current folder.
#pragma once

#include <string>

namespace stencil::report {

// The first of <prefix>/share/stencil/<installed> and <build>/<in_build> that exists, where the
// program runs from <prefix>/bin or <build>/bin; the installed path when neither does (for the message).
[[nodiscard]] std::string shipped_path(const std::string& installed, const std::string& in_build);

// The display's built page.
[[nodiscard]] std::string page_folder();

// "sample:NAME" as the shipped sample part NAME.stl; "" with `error` when there is no such part.
// Anything not starting "sample:" is returned as it is.
[[nodiscard]] std::string resolve_sample_part(const std::string& argument, std::string& error);

}  // namespace stencil::report
