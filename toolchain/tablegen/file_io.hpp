// Files for the table generator: reading whole regular files, and writing outputs all-or-nothing.
#pragma once

#include <cstddef>
#include <string>

namespace stencil::tablegen {

// The size of a regular file; InputError naming the path when it is missing, a directory or
// anything else that is not a regular file.
[[nodiscard]] std::size_t regular_file_size(const std::string& path);

// An output that appears whole or not at all: the constructor creates a temporary file beside
// `path` (so an unwritable place is refused before any work is done), write() fills it, commit()
// flushes it and renames it over `path`. Destroyed uncommitted, it removes the temporary file.
class PendingFile {
 public:
  explicit PendingFile(std::string path);
  ~PendingFile();
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;

  void write(const void* data, std::size_t bytes);
  void commit();
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& what);

  std::string path_;
  std::string temporary_;
  int descriptor_ = -1;
  bool committed_ = false;
};

}  // namespace stencil::tablegen
