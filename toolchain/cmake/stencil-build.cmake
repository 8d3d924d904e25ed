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

# Under the sanitizers the tree is built at -O1 for its compile time, but the core at -O2: the
# engine's lane-wise kernels are most of what the planner's, the engine's and the soak suites run
# (measured back to back, core at -O1 then -O2: motion 93 -> 59 s, soak 62 -> 35 s, engine 39 -> 25 s,
# for 41 s more to compile the core's 22 files). The core's precompiled header is made with it too.
if(STENCIL_SANITIZE)
  set(stencil_core_optimisation -O2)
endif()

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
  target_compile_options(${name} PRIVATE ${stencil_core_optimisation})
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -E env NM=${CMAKE_NM} ${PROJECT_SOURCE_DIR}/linker/check-no-alloc.sh $<TARGET_FILE:${name}>
    COMMENT "Checking ${name} for heap, exceptions, locks, stdio and blocking calls"
    VERBATIM)
endfunction()

# Eigen and the standard headers, parsed once per build tree into precompiled headers instead of in
# every file: Eigen's Core alone takes about 2 s to parse with these flags, and nearly every file of
# the project includes it (measured: a suite's file compiles in 1.3 s instead of 3.0 s). GCC only
# uses a precompiled header made with the same code-generation flags and macros, so there is one
# per set: the core's (no exceptions, no RTTI), the rest of the project's, the suites' (tests/).
# Each is made in a target of its own and reused by the others (-Winvalid-pch: a mismatch fails the
# build instead of silently parsing again). On in the presets CI builds (release and asan), where it
# was measured; the other presets build as before.
option(STENCIL_PCH "Precompile Eigen and the standard headers (GCC)" OFF)
set(STENCIL_PCH_HEADERS
  <algorithm> <array> <atomic> <chrono> <cmath> <cstddef> <cstdint> <cstdio> <cstdlib> <cstring>
  <filesystem> <fstream> <limits> <memory> <random> <sstream> <string> <string_view> <thread>
  <utility> <vector> <Eigen/Core> <Eigen/Geometry>)
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  set(STENCIL_PCH OFF)
endif()

# stencil_pch_holder(NAME [OPTIONS...] [LIBRARIES...]): the target that makes one precompiled header;
# its only source is empty.
function(stencil_pch_holder name)
  cmake_parse_arguments(arg "" "" "OPTIONS;LIBRARIES" ${ARGN})
  set(anchor ${CMAKE_BINARY_DIR}/pch/${name}.cpp)
  if(NOT EXISTS ${anchor})
    file(WRITE ${anchor} "// The precompiled header's own file (toolchain/cmake/stencil-build.cmake).\n")
  endif()
  add_library(${name} OBJECT ${anchor})
  target_compile_definitions(${name} PRIVATE EIGEN_NO_MALLOC)
  target_compile_options(${name} PRIVATE ${arg_OPTIONS})
  target_link_libraries(${name} PRIVATE Eigen3::Eigen stencil_warnings ${arg_LIBRARIES})
  target_precompile_headers(${name} PRIVATE ${STENCIL_PCH_HEADERS})
endfunction()

# stencil_use_pch(TARGET HOLDER): TARGET's files start from HOLDER's precompiled header.
function(stencil_use_pch target holder)
  if(STENCIL_PCH)
    target_compile_definitions(${target} PRIVATE EIGEN_NO_MALLOC)
    target_link_libraries(${target} PRIVATE Eigen3::Eigen)
    target_precompile_headers(${target} REUSE_FROM ${holder})
  endif()
endfunction()

if(STENCIL_PCH)
  stencil_pch_holder(stencil_core_pch OPTIONS ${stencil_core_optimisation} LIBRARIES stencil_core_flags)
  stencil_pch_holder(stencil_pch)
endif()

# stencil_precompile_project(): every library and program of the project outside tests/ starts from
# the project's precompiled header (the core's libraries from the core's). Called once, at the end.
function(stencil_precompile_project)
  if(NOT STENCIL_PCH)
    return()
  endif()
  get_property(core GLOBAL PROPERTY STENCIL_CORE_LIBRARIES)
  get_property(dirs DIRECTORY ${PROJECT_SOURCE_DIR} PROPERTY SUBDIRECTORIES)
  while(dirs)
    list(POP_FRONT dirs dir)
    # The suites have their own (tests/CMakeLists.txt); the bench's FCL reference must not have
    # EIGEN_NO_MALLOC (FCL allocates through Eigen).
    if(dir STREQUAL "${PROJECT_SOURCE_DIR}/tests" OR dir STREQUAL "${PROJECT_SOURCE_DIR}/tests/bench")
      continue()
    endif()
    get_property(children DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
    list(APPEND dirs ${children})
    get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(target IN LISTS targets)
      get_target_property(type ${target} TYPE)
      get_target_property(sources ${target} SOURCES)
      if(NOT type MATCHES "^(STATIC_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$" OR NOT sources MATCHES "[.]cpp"
         OR target MATCHES "^stencil_(core_)?pch$")
        continue()
      endif()
      if(target IN_LIST core)
        stencil_use_pch(${target} stencil_core_pch)
      else()
        stencil_use_pch(${target} stencil_pch)
      endif()
    endforeach()
  endwhile()
endfunction()

# Under the sanitizers, the files that are slow to compile (CLI11, Boost.Beast, toml++, nlohmann's
# JSON) and do little at run time (the programs' options and wiring, the display's web server, the
# rig's configuration file) are built at -O0, without the precompiled header (made at -O1, which
# GCC will not mix): the display's web_server.cpp compiles in 48 s at -O0 against 110 s at -O1
# with the header (measured one after the other), and CI builds this tree once more after the
# release tree. Their work in the suites is parsing options and files and serving a few requests.
set(STENCIL_SANITIZED_AT_O0
  firmware/services/hmi/web_server.cpp
  firmware/programs/sim_options.cpp firmware/programs/rig_options.cpp firmware/programs/display_option.cpp
  firmware/programs/job_folder_option.cpp firmware/programs/rig_control.cpp
  firmware/programs/stencil_sim_main.cpp firmware/programs/stencil_rig_main.cpp
  firmware/programs/stencil_display_main.cpp firmware/programs/stencil_journal_main.cpp
  firmware/programs/stencil_wall_test_main.cpp
  toolchain/tablegen/main.cpp toolchain/same_behaviour/main.cpp
  board/sherline_suzuki/rig_config.cpp)

# stencil_sanitized_at_o0(): applies the list above (each file in its own folder's targets). Called
# once, at the end.
function(stencil_sanitized_at_o0)
  if(NOT STENCIL_SANITIZE)
    return()
  endif()
  # Only folders this configuration added (the options leave some out); appended, so a file's own
  # options (web_server.cpp's warning) stay.
  set(added)
  get_property(pending DIRECTORY ${PROJECT_SOURCE_DIR} PROPERTY SUBDIRECTORIES)
  while(pending)
    list(POP_FRONT pending dir)
    list(APPEND added ${dir})
    get_property(children DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
    list(APPEND pending ${children})
  endwhile()
  foreach(file IN LISTS STENCIL_SANITIZED_AT_O0)
    get_filename_component(folder ${PROJECT_SOURCE_DIR}/${file} DIRECTORY)
    if(folder IN_LIST added)
      set_property(SOURCE ${PROJECT_SOURCE_DIR}/${file} DIRECTORY ${folder} APPEND PROPERTY COMPILE_OPTIONS -O0)
      set_property(SOURCE ${PROJECT_SOURCE_DIR}/${file} DIRECTORY ${folder} PROPERTY SKIP_PRECOMPILE_HEADERS ON)
    endif()
  endforeach()
endfunction()

