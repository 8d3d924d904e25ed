# The real-time x86-64 box beside the mill: native g++, tuned for a generic modern x86-64 and with
# no lazy binding, so no symbol is resolved (and no page touched) for the first time inside the cycle.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_CXX_COMPILER g++ CACHE STRING "C++ compiler")
set(CMAKE_CXX_FLAGS_INIT "-march=x86-64-v2 -mtune=generic")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,-z,now -Wl,-z,relro")
