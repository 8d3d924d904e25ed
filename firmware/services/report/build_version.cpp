#include "firmware/services/report/build_version.hpp"

namespace stencil::report {

std::string version_text(const std::string& program) {
  return program + " " + source_version() + "\nbuilt with " + build_compiler() + ": " + build_flags();
}

}  // namespace stencil::report
