// LoopStatistics: how late the cycle woke and how long it computed, as histograms of 1 us bins up to
// 1 ms with an overflow bin, plus the overrun count. Fixed storage, updated in the cycle.
#pragma once

#include <array>
#include <cstdint>

namespace stencil::control {

// One histogram of microsecond durations: bin i counts [i, i + 1) us for i < kBins, the last bin
// everything of kBins us or more. Percentiles are read from the bins (to the bin's upper edge, so
// they never understate), the maximum exactly.
class MicrosecondHistogram {
 public:
  static constexpr std::uint32_t kBins = 1000;  // 1 us each, up to 1 ms

  // Real-time safe. A negative duration counts as 0 (a clock that went back is not a long wait).
  void add(std::int64_t duration_ns);

  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] std::uint64_t overflow() const { return bins_[kBins]; }
  [[nodiscard]] std::int64_t max_ns() const { return max_ns_; }
  // The upper edge (us) of the bin holding the q-quantile (0 < q <= 1); the exact maximum when it
  // falls in the overflow bin; 0 when empty. Not for the cycle: walks the bins.
  [[nodiscard]] double quantile_us(double q) const;

 private:
  std::array<std::uint64_t, kBins + 1> bins_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

struct LoopStatistics {
  MicrosecondHistogram wakeup_latency;  // how long after its deadline the cycle started
  MicrosecondHistogram compute;         // how long the cycle's step took
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;           // steps that ended after the next period's deadline
  std::uint64_t missed_periods = 0;     // periods skipped because the cycle woke after they were due
};

}  // namespace stencil::control
