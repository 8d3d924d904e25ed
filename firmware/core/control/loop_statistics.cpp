// The cycle's histograms.
#include "firmware/core/control/loop_statistics.hpp"

#include <cmath>

namespace stencil::control {

void MicrosecondHistogram::add(std::int64_t duration_ns) {
  const std::int64_t ns = duration_ns < 0 ? 0 : duration_ns;
  const std::int64_t us = ns / 1000;
  bins_[us >= std::int64_t{kBins} ? kBins : static_cast<std::uint32_t>(us)] += 1;
  ++count_;
  if (ns > max_ns_) {
    max_ns_ = ns;
  }
}

double MicrosecondHistogram::quantile_us(double q) const {
  if (count_ == 0 || !(q > 0.0)) {
    return 0.0;
  }
  // The rank of the q-quantile among count_ samples, 1-based: at least 1, at most count_.
  const double wanted = std::ceil(q * static_cast<double>(count_));
  const auto rank = static_cast<std::uint64_t>(wanted < 1.0 ? 1.0 : wanted);
  std::uint64_t seen = 0;
  for (std::uint32_t bin = 0; bin < kBins; ++bin) {
    seen += bins_[bin];
    if (seen >= rank) {
      return static_cast<double>(bin + 1);
    }
  }
  return static_cast<double>(max_ns_) / 1000.0;
}

}  // namespace stencil::control
