// A part's table file (.stbl), read whole and checked by the firmware's own loader.
#pragma once

#include <string>
#include <vector>

#include "firmware/core/tables/part_tables.hpp"

namespace stencil::app {

// Reads `path` into `bytes` (which `part` then points into) and loads it. False with `error`
// naming the file and, for a bad table, the field.
[[nodiscard]] bool load_table_file(const std::string& path, std::vector<unsigned char>& bytes, tables::PartTables& part,
                                   std::string& error);

}  // namespace stencil::app
