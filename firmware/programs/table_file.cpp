#include "firmware/programs/table_file.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <sstream>

#include "firmware/core/tables/table_loader.hpp"

namespace stencil::app {

std::string describe_refusal(const tables::TableLoadResult& refused) {
  if (refused.expected == tables::kOlderVersion) {
    return "format version " + std::to_string(static_cast<std::uint64_t>(refused.value)) +
           ": regenerate with stencil-tablegen (this build reads format version " +
           std::to_string(tables::kTableFormatVersion) + ")";
  }
  std::ostringstream text;
  text.precision(17);  // a CRC or a byte count whole, a coordinate to its last digit
  text << "not a valid table: " << refused.field << " (at " << refused.index << "): expected " << refused.expected
       << ", found " << refused.value;
  return text.str();
}

bool load_table_file(const std::string& path, std::vector<unsigned char>& bytes, tables::PartTables& part,
                     std::string& error) {
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (in == nullptr) {
    error = path + ": cannot be read";
    return false;
  }
  bytes.clear();
  unsigned char block[65536];
  for (std::size_t n = std::fread(block, 1, sizeof block, in); n > 0; n = std::fread(block, 1, sizeof block, in)) {
    bytes.insert(bytes.end(), block, block + n);
  }
  const bool read_whole = std::ferror(in) == 0;
  std::fclose(in);
  if (!read_whole) {
    error = path + ": cannot be read";
    return false;
  }
  const tables::TableLoadResult loaded =
      tables::load_tables({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, part);
  if (!loaded.ok) {
    error = path + ": " + describe_refusal(loaded);
  }
  return loaded.ok;
}

}  // namespace stencil::app
