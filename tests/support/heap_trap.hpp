// The allocation trap of the real-time tests: every heap entry point wrapped at link time
// (-Wl,--wrap=malloc,... see tests/stencil/CMakeLists.txt), counted while armed. Link
// heap_trap.cpp into a plain program (CppUTest's own operator new would clash).
#pragma once

namespace stencil::test {

void arm_heap_trap(const char* who);  // `who` prefixes the report of each trapped call
void disarm_heap_trap();
[[nodiscard]] unsigned long trapped_heap_calls();

}  // namespace stencil::test
