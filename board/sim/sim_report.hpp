// The simulation's report: JSON for machines, a summary for people, and the stock's heights as CSV;
// the picture that goes beside the report is stock_picture.hpp's, included here for the programs.
#pragma once

#include <string>

#include "board/sim/sim_job.hpp"
#include "board/sim/stock_picture.hpp"
#include "firmware/services/report/provenance.hpp"

namespace stencil::board::sim {

// Writes the report as JSON; false with `error` naming the path on failure.
[[nodiscard]] bool write_report_json(const std::string& path, const SimResult& result,
                                     const report::Provenance& provenance, std::string& error);

// The machined stock's heights as CSV, one Z-map row per line (y rising), mm.
[[nodiscard]] bool write_stock_csv(const std::string& path, const SimResult& result, std::string& error);

// A few lines for the terminal.
[[nodiscard]] std::string summary(const SimResult& result);

}  // namespace stencil::board::sim
