#include "firmware/programs/output_probe.hpp"

#include <cstdio>
#include <fstream>

#include <unistd.h>

namespace stencil::app {

bool probe_writable(const std::string& path, std::string& error) {
  const bool existed = access(path.c_str(), F_OK) == 0;
  std::ofstream probe(path, std::ios::app);
  if (!probe) {
    error = path + ": cannot be written";
    return false;
  }
  probe.close();
  if (!existed) {
    std::remove(path.c_str());
  }
  return true;
}

}  // namespace stencil::app
