# Host build (developer machines, CI, the simulation): the system's g++ for this machine.
set(CMAKE_CXX_COMPILER g++ CACHE STRING "C++ compiler")
