# The fake haptic device's and the fake clock's own tests. Included from tests/fakes/CMakeLists.txt.
stencil_add_test(fake_device_clock_tests
  LABEL unit
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fake_haptic_device_tests.cpp ${CMAKE_CURRENT_LIST_DIR}/fake_clock_tests.cpp
  LIBRARIES stencil_hal)
