# Shared build rules: warnings for the project's own code, the real-time core's flags, the core library helper.

# Warnings are errors in the project's own code; third-party headers come in as SYSTEM includes.
add_library(stencil_warnings INTERFACE)
target_compile_options(stencil_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow
  -Wnon-virtual-dtor -Wcast-align -Wnull-dereference -Wdouble-promotion
  -Werror)

# Results must not change with the compiler's choice to fuse multiply and add, in the core or in
# the offline tools that share its geometry.
add_compile_options(-ffp-contract=off)

# Host builds run on the machine that built them: where it has AVX2 and FMA, the core's lane-wise
# kernels (fixed-size Eigen arrays) run four doubles per instruction instead of two, which more than
# halves the deep-contact query. STENCIL_HOST_ISA=baseline gives binaries for any x86-64. The
# compiler still never fuses multiply and add (above); the real-time box has its own toolchain file.
set(STENCIL_HOST_ISA auto CACHE STRING "Host x86-64 vector extensions: auto (AVX2+FMA when this machine has them), avx2, baseline")
set_property(CACHE STENCIL_HOST_ISA PROPERTY STRINGS auto avx2 baseline)
if(STENCIL_HOST_TOOLCHAIN AND CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64)$")
  set(stencil_use_avx2 OFF)
  if(STENCIL_HOST_ISA STREQUAL "avx2")
    set(stencil_use_avx2 ON)
  elseif(STENCIL_HOST_ISA STREQUAL "auto")
    include(CheckCXXSourceRuns)
    check_cxx_source_runs([[
      int main() {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? 0 : 1;
      }]] STENCIL_HOST_HAS_AVX2_FMA)
    set(stencil_use_avx2 ${STENCIL_HOST_HAS_AVX2_FMA})
  elseif(NOT STENCIL_HOST_ISA STREQUAL "baseline")
    message(FATAL_ERROR "STENCIL_HOST_ISA is '${STENCIL_HOST_ISA}': expected auto, avx2 or baseline")
  endif()
  if(stencil_use_avx2)
    add_compile_options(-mavx2 -mfma)
  endif()
  message(STATUS "Host vector extensions: ${STENCIL_HOST_ISA} -> AVX2+FMA ${stencil_use_avx2}")
endif()

if(STENCIL_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()

# The 1 kHz core: no exceptions, no RTTI, and any dynamic Eigen allocation aborts. The core never
# reads errno or the floating-point exception flags, so sqrt need not set the one and selects need
# not preserve the other: then sqrt is one instruction and the per-point loops vectorise. Results
# are unchanged (IEEE operations are exact-rounded either way).
add_library(stencil_core_flags INTERFACE)
target_compile_options(stencil_core_flags INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti -fno-math-errno -fno-trapping-math>)

# stencil_core_library(NAME SOURCES...): a static library of the allocation-free core. It is
# checked right after it is built (every preset, cross builds included, with that toolchain's nm)
# and again by the ctest in linker/: the build fails if any of its objects references the heap,
# exceptions, locks, stdio or blocking calls.
function(stencil_core_library name)
  add_library(${name} STATIC ${ARGN})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  # EIGEN_NO_MALLOC travels with the headers (one definition everywhere); the code-generation flags
  # are the core's own.
  target_compile_definitions(${name} PUBLIC EIGEN_NO_MALLOC)
  target_link_libraries(${name} PUBLIC Eigen3::Eigen PRIVATE stencil_core_flags stencil_warnings)
  set_property(GLOBAL APPEND PROPERTY STENCIL_CORE_LIBRARIES ${name})
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -E env NM=${CMAKE_NM} ${PROJECT_SOURCE_DIR}/linker/check-no-alloc.sh $<TARGET_FILE:${name}>
    COMMENT "Checking ${name} for heap, exceptions, locks, stdio and blocking calls"
    VERBATIM)
endfunction()
