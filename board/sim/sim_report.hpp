// The simulation's report: JSON for machines, a summary for people, and a picture of the machined
// stock beside the part with gouges in a warning colour.
#pragma once

#include <string>

#include "board/sim/sim_job.hpp"
#include "firmware/services/report/provenance.hpp"

namespace stencil::board::sim {

// Writes the report as JSON; false with `error` naming the path on failure.
[[nodiscard]] bool write_report_json(const std::string& path, const SimResult& result,
                                     const report::Provenance& provenance, std::string& error);

// The machined stock's heights as CSV, one Z-map row per line (y rising), mm.
[[nodiscard]] bool write_stock_csv(const std::string& path, const SimResult& result, std::string& error);

// A few lines for the terminal.
[[nodiscard]] std::string summary(const SimResult& result);

// Top views side by side, as SVG: the stock as machined (darker is lower), the part's top, and
// every cell cut below the part's surface by more than 5 um in red.
[[nodiscard]] bool write_picture_svg(const std::string& path, const SimResult& result, std::string& error);

}  // namespace stencil::board::sim
