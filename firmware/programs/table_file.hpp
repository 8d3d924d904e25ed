// A part's table file (.stbl), read whole and checked by the firmware's own loader.
#pragma once

#include <string>
#include <vector>

#include "firmware/core/tables/part_tables.hpp"
#include "firmware/core/tables/table_loader.hpp"

namespace stencil::app {

// A loader's refusal in words: "format version N: regenerate with stencil-tablegen" for a table of
// an older format, else the field, where, what was expected and what was found.
[[nodiscard]] std::string describe_refusal(const tables::TableLoadResult& refused);

// Reads `path` into `bytes` (which `part` then points into) and loads it. False with `error`
// naming the file and, for a bad table, the field.
[[nodiscard]] bool load_table_file(const std::string& path, std::vector<unsigned char>& bytes, tables::PartTables& part,
                                   std::string& error);

}  // namespace stencil::app
