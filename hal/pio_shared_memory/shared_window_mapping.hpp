// SharedWindowMapping: init-time opening and memory-mapping of the PIO card's shared window (a UIO
// device on the rig, a file or memfd in tests), and the check of its header. Not real-time: it
// allocates, opens, maps and unmaps; the cycle only uses the SharedWindow it hands out.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "hal/pio_shared_memory/shared_window_layout.hpp"

namespace stencil::hal::pio_shared_memory {

class SharedWindowMapping {
 public:
  SharedWindowMapping(const SharedWindowMapping&) = delete;
  SharedWindowMapping& operator=(const SharedWindowMapping&) = delete;
  ~SharedWindowMapping();  // unmaps and closes

  // Maps kWindowBytes of `path` read-write and shared, from `offset_bytes` (a multiple of the page
  // size; for /dev/uioN, map N is at N * page size). A regular file shorter than the window is an
  // error. With `require_header`, the header must carry the magic, version and size the device
  // writes at power-up (the host's open); without, it is not looked at (the device's own open).
  // On failure: null, and `error` names the path, the byte and what was expected.
  [[nodiscard]] static std::unique_ptr<SharedWindowMapping> open(const std::string& path, std::size_t offset_bytes,
                                                                 bool require_header, std::string& error);

  // A new anonymous memory file of kWindowBytes, zeroed, mapped: the window of a test or of a host
  // simulation. path() names it through /proc/self/fd so a second open() maps the same memory.
  [[nodiscard]] static std::unique_ptr<SharedWindowMapping> create_memfd(const std::string& name, std::string& error);

  [[nodiscard]] SharedWindow& window() const { return *window_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  SharedWindowMapping(int fd, void* base, std::size_t mapped_bytes, std::string path);

  int fd_;
  void* base_;
  std::size_t mapped_bytes_;
  SharedWindow* window_;
  std::string path_;
};

// Empty when the header is what the device writes at power-up; otherwise what is wrong, e.g.
// "/dev/uio0: byte 0 (magic): 0x00000000, expected 0x50415448 (the device has not initialised the window)".
[[nodiscard]] std::string check_window_header(SharedWindow& window, const std::string& name);

}  // namespace stencil::hal::pio_shared_memory
