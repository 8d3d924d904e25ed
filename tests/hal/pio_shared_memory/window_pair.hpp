// A test's shared window: a memfd mapped twice, once for the simulated device (which initialises the
// header) and once for the host (which checks it), as on the rig where two sides map one card.
#pragma once

#include <memory>
#include <string>

#include "hal/pio_shared_memory/shared_window_mapping.hpp"

namespace stencil::test {

struct WindowPair {
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> device;
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> host;  // open after the device's init
  std::string error;
};

inline WindowPair make_device_window() {
  WindowPair pair;
  pair.device = hal::pio_shared_memory::SharedWindowMapping::create_memfd("haptic-test-window", pair.error);
  return pair;
}

inline void open_host_window(WindowPair& pair) {
  pair.host = hal::pio_shared_memory::SharedWindowMapping::open(pair.device->path(), 0, true, pair.error);
}

}  // namespace stencil::test
