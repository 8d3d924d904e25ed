// A fresh folder under /tmp for one test, removed with everything in it when the object goes.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace stencil::testing {

class TempFolder {
 public:
  explicit TempFolder(const std::string& prefix = "stencil-tests") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (mkdtemp(pattern.data()) != nullptr) {
      dir = pattern;
    }
  }
  ~TempFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  std::filesystem::path dir;  // empty when it could not be made
  [[nodiscard]] std::string path() const { return dir.string(); }
  [[nodiscard]] std::string file(const std::string& name) const { return (dir / name).string(); }
};

}  // namespace stencil::testing
