// The cycle's histograms: bins of 1 us, an overflow bin, quantiles that never understate.
#include "firmware/core/control/loop_statistics.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::MicrosecondHistogram;

TEST_GROUP(MicrosecondHistogram){};

TEST(MicrosecondHistogram, AnEmptyHistogramReportsZero) {
  const MicrosecondHistogram histogram;
  LONGS_EQUAL(0, histogram.count());
  DOUBLES_EQUAL(0.0, histogram.quantile_us(0.5), 0.0);
}

TEST(MicrosecondHistogram, QuantilesAreTheUpperEdgeOfTheirBin) {
  MicrosecondHistogram histogram;
  for (int i = 0; i < 90; ++i) {
    histogram.add(10'400);  // 10.4 us: bin [10, 11)
  }
  for (int i = 0; i < 10; ++i) {
    histogram.add(250'000);  // 250 us
  }
  LONGS_EQUAL(100, histogram.count());
  DOUBLES_EQUAL(11.0, histogram.quantile_us(0.5), 0.0);
  DOUBLES_EQUAL(11.0, histogram.quantile_us(0.9), 0.0);
  DOUBLES_EQUAL(251.0, histogram.quantile_us(0.91), 0.0);
  DOUBLES_EQUAL(251.0, histogram.quantile_us(1.0), 0.0);
  LONGS_EQUAL(250'000, histogram.max_ns());
}

TEST(MicrosecondHistogram, BeyondAMillisecondGoesToTheOverflowBinAndTheMaximumIsExact) {
  MicrosecondHistogram histogram;
  histogram.add(5'000);
  histogram.add(1'000'000);  // exactly 1 ms: the overflow bin
  histogram.add(3'456'789);
  LONGS_EQUAL(2, histogram.overflow());
  LONGS_EQUAL(3'456'789, histogram.max_ns());
  DOUBLES_EQUAL(3456.789, histogram.quantile_us(1.0), 1e-9);
  DOUBLES_EQUAL(6.0, histogram.quantile_us(0.3), 0.0);
}

TEST(MicrosecondHistogram, ANegativeDurationCountsAsZero) {
  MicrosecondHistogram histogram;
  histogram.add(-7'000);
  LONGS_EQUAL(1, histogram.count());
  DOUBLES_EQUAL(1.0, histogram.quantile_us(1.0), 0.0);
  LONGS_EQUAL(0, histogram.max_ns());
}
