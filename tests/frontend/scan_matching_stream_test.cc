#include "frontend/scan_matching_stream.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace roamlab::frontend {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A room scanned from two places 5 cm apart: the stream's row is the velocity of eq. 7's motion, stamped at the middle
// of the pair; a scan without returns does not match and is counted.
TEST(ScanMatchingStreamTest, RowsAtTheMiddleOfEachPairAndFailuresCounted) {
  ScanGeometry g;
  // A square room of 6 m seen from its centre, and from 0.05 m further along x.
  const auto scan = [&g](double x) {
    std::vector<double> ranges(static_cast<std::size_t>(g.beams));
    for (int k = 0; k < g.beams; ++k) {
      const double a = g.Angle(k);
      const double c = std::cos(a), s = std::sin(a);
      double r = 1e9;
      if (c > 1e-9) r = std::min(r, (3.0 - x) / c);
      if (c < -1e-9) r = std::min(r, (-3.0 - x) / c);
      if (std::abs(s) > 1e-9) r = std::min(r, 3.0 / std::abs(s));
      ranges[static_cast<std::size_t>(k)] = r <= g.max_range_m ? r : kNaN;
    }
    return ranges;
  };
  ScanMatchingStream stream("scan_matching", 10.0);
  EXPECT_FALSE(stream.AddScan(Time::FromSeconds(0.0), g, scan(0.0)));
  EXPECT_TRUE(stream.AddScan(Time::FromSeconds(0.1), g, scan(0.05)));
  EXPECT_FALSE(stream.AddScan(Time::FromSeconds(0.2), g, std::vector<double>(static_cast<std::size_t>(g.beams), kNaN)));
  EXPECT_EQ(stream.failed_matches(), 1);
  const recording::Stream out = stream.TakeStream();
  ASSERT_EQ(out.t.size(), 1u);
  EXPECT_EQ(out.t[0], Time::FromSeconds(0.05));
  EXPECT_NEAR(out.values(0, 0), 0.5, 0.02);
  EXPECT_NEAR(out.values(0, 1), 0.0, 0.02);
  EXPECT_EQ(out.values(0, 2), 0.0);
  EXPECT_LT(out.info.noise.at("sigma_mps"), 1e-3);  // noise-free scans
}

}  // namespace
}  // namespace roamlab::frontend
