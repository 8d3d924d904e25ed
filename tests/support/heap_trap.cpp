// Link-time wrappers of malloc, calloc, realloc, free and operator new/new[] that count calls made
// while the trap is armed.
#include "tests/support/heap_trap.hpp"

#include <cstddef>
#include <cstdio>

namespace {
bool armed = false;
const char* owner = "heap_trap";
unsigned long trapped = 0;
void note(const char* what) {
  if (armed) {
    ++trapped;
    armed = false;  // report once, without recursing through stdio's own allocations
    std::fprintf(stderr, "%s: %s called while the trap was armed\n", owner, what);
    armed = true;
  }
}
}  // namespace

namespace stencil::test {
void arm_heap_trap(const char* who) {
  owner = who;
  armed = true;
}
void disarm_heap_trap() { armed = false; }
unsigned long trapped_heap_calls() { return trapped; }
}  // namespace stencil::test

extern "C" {
void* __real_malloc(std::size_t);
void* __real_calloc(std::size_t, std::size_t);
void* __real_realloc(void*, std::size_t);
void __real_free(void*);
void* __wrap_malloc(std::size_t size) { note("malloc"); return __real_malloc(size); }
void* __wrap_calloc(std::size_t count, std::size_t size) { note("calloc"); return __real_calloc(count, size); }
void* __wrap_realloc(void* pointer, std::size_t size) { note("realloc"); return __real_realloc(pointer, size); }
void __wrap_free(void* pointer) { note("free"); __real_free(pointer); }
void* __real__Znwm(std::size_t);
void* __real__Znam(std::size_t);
void* __wrap__Znwm(std::size_t size) { note("operator new"); return __real__Znwm(size); }
void* __wrap__Znam(std::size_t size) { note("operator new[]"); return __real__Znam(size); }
}
