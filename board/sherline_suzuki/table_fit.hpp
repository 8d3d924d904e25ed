// Tables against the rig they are to be cut on: the part inside the configured travel (from the
// work offset) and inside the device's reach, the tables' tool no longer than it sticks out of its
// holder. Checked at start-up, before anything is opened; a mismatch names both numbers.
#pragma once

#include <string>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::board::sherline_suzuki {

struct TableFitJob {
  std::array<double, 3> home_world_mm;  // the work offset: the tool tip in the part's frame at home
  double tool_stick_out_mm = 0.0;       // 0: not given (the holder is not checked)
  double reference_stick_out_mm = 0.0;
};

// False with `error` ("<tables>: ...") naming the axis, the part's extent and the configured one.
[[nodiscard]] bool check_tables_fit(const tables::TableHeader& header, const std::string& tables_name,
                                    const RigFacts& facts, const TableFitJob& job, std::string& error);

// Where the tool tip can go, world mm: the configured travel from the work offset, per axis.
void configured_travel(const RigFacts& facts, const TableFitJob& job, std::array<double, 3>& low_mm,
                       std::array<double, 3>& high_mm);

// The stock block (world mm) inside the configured travel from the work offset: false with `error`
// naming the axis, the stock's extent and the travel's.
[[nodiscard]] bool check_stock_fit(const std::array<double, 3>& low_mm, const std::array<double, 3>& high_mm,
                                   const RigFacts& facts, const TableFitJob& job, std::string& error);

}  // namespace stencil::board::sherline_suzuki
