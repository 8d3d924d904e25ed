// Opening, mapping and checking the PIO card's shared window (init-time only).
#include "hal/pio_shared_memory/shared_window_mapping.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <atomic>
#include <cstring>
#include <utility>

namespace stencil::hal::pio_shared_memory {

namespace {

std::string hex_word(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

}  // namespace

SharedWindowMapping::SharedWindowMapping(int fd, void* base, std::size_t mapped_bytes, std::string path)
    : fd_(fd),
      base_(base),
      mapped_bytes_(mapped_bytes),
      window_(static_cast<SharedWindow*>(base)),
      path_(std::move(path)) {}

SharedWindowMapping::~SharedWindowMapping() {
  ::munmap(base_, mapped_bytes_);
  ::close(fd_);
}

std::string check_window_header(SharedWindow& window, const std::string& name) {
  // The device may still be writing it: read each word once, atomically.
  auto load = [](std::uint32_t& word) { return std::atomic_ref<std::uint32_t>(word).load(std::memory_order_acquire); };
  const std::uint32_t magic = load(window.header.magic);
  if (magic != kWindowMagic) {
    return name + ": byte 0 (magic): " + hex_word(magic) + ", expected " + hex_word(kWindowMagic) +
           " (the device has not initialised the window, or this is not the PIO card's window)";
  }
  const std::uint32_t version = load(window.header.layout_version);
  if (version != kLayoutVersion) {
    return name + ": byte 4 (layout version): " + std::to_string(version) + ", expected " +
           std::to_string(kLayoutVersion);
  }
  const std::uint32_t size = load(window.header.window_bytes);
  if (size != kWindowBytes) {
    return name + ": byte 8 (window size): " + std::to_string(size) + " bytes, expected " +
           std::to_string(kWindowBytes);
  }
  return {};
}

std::unique_ptr<SharedWindowMapping> SharedWindowMapping::open(const std::string& path, std::size_t offset_bytes,
                                                               bool require_header, std::string& error) {
  const long page_bytes = ::sysconf(_SC_PAGESIZE);
  if (page_bytes <= 0 || offset_bytes % static_cast<std::size_t>(page_bytes) != 0) {
    error = path + ": offset " + std::to_string(offset_bytes) + " is not a multiple of the page size";
    return nullptr;
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    error = path + ": cannot open read-write: " + std::strerror(errno);
    return nullptr;
  }
  struct stat status {};
  if (::fstat(fd, &status) == 0 && S_ISREG(status.st_mode) &&
      static_cast<std::size_t>(status.st_size) < offset_bytes + kWindowBytes) {
    error = path + ": " + std::to_string(status.st_size) + " bytes, expected at least " +
            std::to_string(offset_bytes + kWindowBytes) + " (the window from byte " + std::to_string(offset_bytes) + ")";
    ::close(fd);
    return nullptr;
  }
  void* base = ::mmap(nullptr, kWindowBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, static_cast<off_t>(offset_bytes));
  if (base == MAP_FAILED) {
    error = path + ": cannot map " + std::to_string(kWindowBytes) + " bytes at offset " + std::to_string(offset_bytes) +
            ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  std::unique_ptr<SharedWindowMapping> mapping(new SharedWindowMapping(fd, base, kWindowBytes, path));
  if (require_header) {
    error = check_window_header(mapping->window(), path);
    if (!error.empty()) return nullptr;
  }
  return mapping;
}

std::unique_ptr<SharedWindowMapping> SharedWindowMapping::create_memfd(const std::string& name, std::string& error) {
  const int fd = ::memfd_create(name.c_str(), MFD_CLOEXEC);
  if (fd < 0) {
    error = "memfd " + name + ": cannot create: " + std::strerror(errno);
    return nullptr;
  }
  if (::ftruncate(fd, static_cast<off_t>(kWindowBytes)) != 0) {
    error = "memfd " + name + ": cannot size to " + std::to_string(kWindowBytes) + " bytes: " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  void* base = ::mmap(nullptr, kWindowBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) {
    error = "memfd " + name + ": cannot map: " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  const std::string path = "/proc/" + std::to_string(::getpid()) + "/fd/" + std::to_string(fd);
  return std::unique_ptr<SharedWindowMapping>(new SharedWindowMapping(fd, base, kWindowBytes, path));
}

}  // namespace stencil::hal::pio_shared_memory
