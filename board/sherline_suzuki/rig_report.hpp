// The rig's report: the figures every job reports (firmware/services/report), and what only the
// rig's run says: the first fault, the resets taken and refused, how long it ran.
#pragma once

#include <string>

#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/services/report/provenance.hpp"

namespace stencil::board::sherline_suzuki {

// `machine_error`: the link's last error ("" when none). False with `error` naming the path.
[[nodiscard]] bool write_rig_report(const std::string& path, const RigResult& result, const std::string& machine_error,
                                    const report::Provenance& provenance, std::string& error);

}  // namespace stencil::board::sherline_suzuki
