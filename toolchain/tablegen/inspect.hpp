// --inspect: validates a table file with the firmware's own loader and describes it.
#pragma once

#include <iosfwd>
#include <string>

namespace stencil::tablegen {

// Loads `path` with tables::load_tables. On success writes a summary (JSON when `json`) to `out`
// and returns 0; on failure writes one error line naming the file, field and value to `err` and
// returns 2.
int inspect_table(const std::string& path, bool json, std::ostream& out, std::ostream& err);

}  // namespace stencil::tablegen
