# Host build (developer machines, CI, the simulation): the system's g++ for this machine.
set(CMAKE_CXX_COMPILER g++ CACHE STRING "C++ compiler")
# Builds made with this file run where they are built (see STENCIL_HOST_ISA in stencil-build.cmake).
set(STENCIL_HOST_TOOLCHAIN ON)
