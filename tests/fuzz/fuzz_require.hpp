// The fuzz targets' promise check: a broken promise stops the run where libFuzzer sees it (a trap is
// a crash with the input saved), whatever the build's assertions.
#pragma once

namespace stencil::fuzz {

inline void require(bool promise) {
  if (!promise) {
    __builtin_trap();
  }
}

}  // namespace stencil::fuzz
