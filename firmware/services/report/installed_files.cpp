#include "firmware/services/report/installed_files.hpp"

#include <filesystem>
#include <system_error>

#ifndef STENCIL_INSTALL_DATADIR
#define STENCIL_INSTALL_DATADIR "share"
#endif
#ifndef STENCIL_INSTALL_FULL_DATADIR
#define STENCIL_INSTALL_FULL_DATADIR "/usr/share"
#endif

namespace stencil::report {

std::string shipped_path(const std::string& installed, const std::string& in_build) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec || !self.is_absolute()) {  // no /proc: the package's place, never the current folder
    return (std::filesystem::path(STENCIL_INSTALL_FULL_DATADIR) / "stencil" / installed).string();
  }
  const std::filesystem::path prefix = self.parent_path().parent_path();
  const std::filesystem::path shipped = prefix / STENCIL_INSTALL_DATADIR / "stencil" / installed;
  if (std::filesystem::exists(shipped, ec)) {
    return shipped.string();
  }
  const std::filesystem::path built = prefix / in_build;
  return std::filesystem::exists(built, ec) ? built.string() : shipped.string();
}

std::string page_folder() { return shipped_path("page", "hmi"); }

std::string resolve_sample_part(const std::string& argument, std::string& error) {
  static constexpr std::string_view kPrefix = "sample:";
  if (argument.compare(0, kPrefix.size(), kPrefix) != 0) {
    return argument;
  }
  const std::string name = argument.substr(kPrefix.size());
  const std::string folder = shipped_path("parts", "parts");
  std::error_code ec;
  if (!name.empty() && name.find('/') == std::string::npos) {
    const std::filesystem::path part = std::filesystem::path(folder) / (name + ".stl");
    if (std::filesystem::is_regular_file(part, ec)) {
      return part.string();
    }
  }
  std::string names;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    if (entry.path().extension() == ".stl") {
      names += (names.empty() ? "" : ", ") + entry.path().stem().string();
    }
  }
  error = argument + ": no such sample part in " + folder + " (expected sample:NAME with NAME one of " +
          (names.empty() ? std::string("none: the folder is missing") : names) + ")";
  return "";
}

}  // namespace stencil::report
