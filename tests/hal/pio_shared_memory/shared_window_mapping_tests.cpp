// Opening and mapping the PIO card's shared window (hal/pio_shared_memory/shared_window_mapping.cpp)
// on memfds and files: the header check at the host's open (each word named by its byte), files too
// short, offsets that are not whole pages, missing paths, and two mappings of one memfd sharing memory.
#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "hal/pio_shared_memory/pio_device_side.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace pio = hal::pio_shared_memory;

TEST_GROUP(SharedWindowMapping) {
  test::WindowPair windows = test::make_device_window();
};

TEST(SharedWindowMapping, AMemfdWindowStartsZeroedAndASecondOpenMapsTheSameMemory) {
  CHECK_TRUE(windows.device != nullptr);
  CHECK_EQUAL(0U, windows.device->window().header.magic);
  CHECK_EQUAL(0U, windows.device->window().pose.sequence);
  STRCMP_CONTAINS("/fd/", windows.device->path().c_str());

  std::string error;
  const auto other = pio::SharedWindowMapping::open(windows.device->path(), 0, false, error);
  CHECK_TEXT(other != nullptr, error.c_str());
  windows.device->window().pose.sample_counter = 4242U;
  CHECK_EQUAL(4242U, other->window().pose.sample_counter);
  other->window().command.host_heartbeat = 17U;
  CHECK_EQUAL(17U, windows.device->window().command.host_heartbeat);
}

TEST(SharedWindowMapping, HostRefusesAWindowTheDeviceHasNotInitialised) {
  CHECK_TRUE(windows.device != nullptr);
  test::open_host_window(windows);
  CHECK_TRUE(windows.host == nullptr);
  STRCMP_CONTAINS("byte 0 (magic): 0x00000000, expected 0x50415448", windows.error.c_str());
  STRCMP_CONTAINS(windows.device->path().c_str(), windows.error.c_str());

  pio::PioDeviceSide(windows.device->window()).initialise_header();
  test::open_host_window(windows);
  CHECK_TRUE(windows.host != nullptr);
  CHECK_EQUAL(pio::kWindowMagic, windows.host->window().header.magic);
}

TEST(SharedWindowMapping, TheDevicesOwnOpenDoesNotLookAtTheHeader) {
  std::string error;
  CHECK_TRUE(pio::SharedWindowMapping::open(windows.device->path(), 0, false, error) != nullptr);
  CHECK_TRUE(pio::SharedWindowMapping::open(windows.device->path(), 0, true, error) == nullptr);
}

TEST(SharedWindowMapping, HostRefusesAWindowOfAnotherLayoutVersion) {
  pio::PioDeviceSide(windows.device->window()).initialise_header();
  windows.device->window().header.layout_version = pio::kLayoutVersion + 1;
  test::open_host_window(windows);
  CHECK_TRUE(windows.host == nullptr);
  STRCMP_CONTAINS("byte 4 (layout version): 2, expected 1", windows.error.c_str());
}

TEST(SharedWindowMapping, HostRefusesAWindowOfAnotherSize) {
  pio::PioDeviceSide(windows.device->window()).initialise_header();
  windows.device->window().header.window_bytes = 256;
  STRCMP_EQUAL("card: byte 8 (window size): 256 bytes, expected 192",
               pio::check_window_header(windows.device->window(), "card").c_str());
  windows.device->window().header.window_bytes = pio::kWindowBytes;
  STRCMP_EQUAL("", pio::check_window_header(windows.device->window(), "card").c_str());
}

TEST(SharedWindowMapping, OpeningAFileShorterThanTheWindowNamesBothSizes) {
  std::string error;
  CHECK_TRUE(pio::SharedWindowMapping::open("/dev/null", 0, false, error) == nullptr);
  CHECK_TRUE(!error.empty());
  char path[] = "/tmp/haptic-short-window-XXXXXX";
  const int fd = ::mkstemp(path);
  CHECK_TRUE(fd >= 0);
  CHECK_EQUAL(0, ::ftruncate(fd, 100));
  ::close(fd);
  CHECK_TRUE(pio::SharedWindowMapping::open(path, 0, false, error) == nullptr);
  ::unlink(path);
  STRCMP_CONTAINS("100 bytes, expected at least 192", error.c_str());
}

TEST(SharedWindowMapping, AWindowAtAPageOffsetOfALongerFileIsMappedFromThere) {
  const long page = ::sysconf(_SC_PAGESIZE);
  char path[] = "/tmp/haptic-offset-window-XXXXXX";
  const int fd = ::mkstemp(path);
  CHECK_TRUE(fd >= 0);
  CHECK_EQUAL(0, ::ftruncate(fd, page + 100));
  std::string error;
  // The window would run past the end of the file from this offset.
  CHECK_TRUE(pio::SharedWindowMapping::open(path, static_cast<std::size_t>(page), false, error) == nullptr);
  STRCMP_CONTAINS("(the window from byte", error.c_str());
  CHECK_EQUAL(0, ::ftruncate(fd, 2 * page));
  const std::uint32_t marker = 0xC0FFEEU;
  CHECK_EQUAL(static_cast<ssize_t>(sizeof marker), ::pwrite(fd, &marker, sizeof marker, page));
  ::close(fd);
  const auto mapping = pio::SharedWindowMapping::open(path, static_cast<std::size_t>(page), false, error);
  ::unlink(path);
  CHECK_TEXT(mapping != nullptr, error.c_str());
  CHECK_EQUAL(0xC0FFEEU, mapping->window().header.magic);  // the first word of the second page
}

TEST(SharedWindowMapping, AnOffsetThatIsNotAWholePageIsRefusedBeforeAnythingIsOpened) {
  std::string error;
  CHECK_TRUE(pio::SharedWindowMapping::open("/nonexistent/uio0", 100, false, error) == nullptr);
  STRCMP_EQUAL("/nonexistent/uio0: offset 100 is not a multiple of the page size", error.c_str());
}

TEST(SharedWindowMapping, AMissingPathIsNamedWithTheReason) {
  std::string error;
  CHECK_TRUE(pio::SharedWindowMapping::open("/nonexistent/uio0", 0, true, error) == nullptr);
  STRCMP_CONTAINS("/nonexistent/uio0: cannot open read-write: ", error.c_str());
  STRCMP_CONTAINS("No such file", error.c_str());
}
