# Run at every build (cmake -P, from firmware/services/report): writes OUT, the values behind
# firmware/services/report/build_version.hpp, and rewrites it only when they change, so a build with
# nothing new recompiles nothing. In: SOURCE_DIR, OUT, COMPILER, FLAGS.
execute_process(COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --tags
                OUTPUT_VARIABLE version OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE status)
if(NOT status EQUAL 0 OR version STREQUAL "")
  set(version "unknown (built outside a git checkout)")
endif()
string(REPLACE "\"" "\\\"" flags "${FLAGS}")
set(text "// Generated at build time by toolchain/cmake/stencil-version.cmake: do not edit.
#include \"firmware/services/report/build_version.hpp\"

namespace stencil::report {
const char* source_version() { return \"${version}\"; }
const char* build_compiler() { return \"${COMPILER}\"; }
const char* build_flags() { return \"${flags}\"; }
}  // namespace stencil::report
")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
