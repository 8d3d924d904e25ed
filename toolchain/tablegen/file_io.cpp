// Regular-file checks and the all-or-nothing output file.
#include "toolchain/tablegen/file_io.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {

std::size_t regular_file_size(const std::string& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    throw InputError(path + ": cannot open (" + std::strerror(errno) + ")");
  }
  if (S_ISDIR(status.st_mode)) {
    throw InputError(path + ": is a directory; expected a file");
  }
  if (!S_ISREG(status.st_mode)) {
    throw InputError(path + ": is not a regular file");
  }
  return static_cast<std::size_t>(status.st_size);
}

PendingFile::PendingFile(std::string path) : path_(std::move(path)), temporary_(path_ + ".partial-XXXXXX") {
  struct stat status {};
  if (::stat(path_.c_str(), &status) == 0 && S_ISDIR(status.st_mode)) {
    throw InputError(path_ + ": is a directory; expected a file name to write");
  }
  descriptor_ = ::mkstemp(temporary_.data());
  if (descriptor_ < 0) {
    throw InputError(path_ + ": cannot write the output here (" + std::strerror(errno) + ")");
  }
}

PendingFile::~PendingFile() {
  if (descriptor_ >= 0) {
    ::close(descriptor_);
  }
  if (!committed_) {
    ::unlink(temporary_.c_str());
  }
}

void PendingFile::fail(const std::string& what) {
  const std::string reason = std::strerror(errno);
  throw InputError(path_ + ": " + what + " (" + reason + "); nothing was written");
}

void PendingFile::write(const void* data, std::size_t bytes) {
  const auto* at = static_cast<const unsigned char*>(data);
  std::size_t written = 0;
  while (written < bytes) {
    const ssize_t result = ::write(descriptor_, at + written, bytes - written);
    if (result < 0) {
      if (errno == EINTR) {
        continue;
      }
      fail("cannot write");
    }
    written += static_cast<std::size_t>(result);
  }
}

void PendingFile::commit() {
  if (::fchmod(descriptor_, 0644) != 0 || ::fsync(descriptor_) != 0) {
    fail("cannot flush");
  }
  const int descriptor = descriptor_;
  descriptor_ = -1;
  if (::close(descriptor) != 0) {
    fail("cannot close");
  }
  if (::rename(temporary_.c_str(), path_.c_str()) != 0) {
    fail("cannot replace");
  }
  committed_ = true;
}

}  // namespace stencil::tablegen
