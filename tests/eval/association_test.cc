#include "eval/association.h"

#include <gtest/gtest.h>

namespace roamlab::eval {
namespace {

std::vector<Time> Stamps(std::int64_t first_ns, std::int64_t step_ns, int count) {
  std::vector<Time> t;
  for (int i = 0; i < count; ++i) t.push_back(Time::FromNanoseconds(first_ns + i * step_ns));
  return t;
}

TEST(AssociationTest, IdenticalStampsMatchOneToOne) {
  const std::vector<Time> t = Stamps(0, 10'000'000, 5);
  const Association a = AssociateByTime(t, t, AssociationOptions{});
  ASSERT_EQ(a.matched(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(a.estimate_index[i], i);
    EXPECT_EQ(a.reference_index[i], i);
  }
  EXPECT_EQ(a.max_time_difference_s, 0.0);
  EXPECT_EQ(a.estimate_size, 5u);
  EXPECT_EQ(a.reference_size, 5u);
}

TEST(AssociationTest, ToleranceDecidesWhetherShiftedStampsMatch) {
  const std::vector<Time> reference = Stamps(0, 10'000'000, 6);
  const std::vector<Time> estimate = Stamps(3'000'000, 10'000'000, 6);  // 3 ms late
  EXPECT_EQ(AssociateByTime(estimate, reference, AssociationOptions{0.0}).matched(), 0u);
  EXPECT_EQ(AssociateByTime(estimate, reference, AssociationOptions{0.002}).matched(), 0u);
  const Association a = AssociateByTime(estimate, reference, AssociationOptions{0.004});
  ASSERT_EQ(a.matched(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(a.reference_index[i], i);
  EXPECT_NEAR(a.max_time_difference_s, 0.003, 1e-12);
}

TEST(AssociationTest, FasterEstimateKeepsTheCloserPoseForEachReference) {
  // Reference at 0, 20, 40 ms; estimate at 1, 11, 21, 31, 41 ms. With 10 ms tolerance 1 -> 0, 21 -> 20, 41 -> 40;
  // 11 and 31 are 9 ms from 20 and 40 (and 11 from 0 and 20), so they lose to the closer ones.
  const std::vector<Time> reference = Stamps(0, 20'000'000, 3);
  const std::vector<Time> estimate = Stamps(1'000'000, 10'000'000, 5);
  const Association a = AssociateByTime(estimate, reference, AssociationOptions{0.010});
  ASSERT_EQ(a.matched(), 3u);
  EXPECT_EQ(a.estimate_index, (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(a.reference_index, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_NEAR(a.max_time_difference_s, 0.001, 1e-12);
}

TEST(AssociationTest, PosesOutsideTheReferenceSpanStayUnmatched) {
  const std::vector<Time> reference = Stamps(100'000'000, 100'000'000, 3);  // 0.1, 0.2, 0.3 s
  const std::vector<Time> estimate = Stamps(0, 100'000'000, 6);             // 0 ... 0.5 s
  const Association a = AssociateByTime(estimate, reference, AssociationOptions{0.01});
  EXPECT_EQ(a.matched(), 3u);
  EXPECT_EQ(a.estimate_index, (std::vector<std::size_t>{1, 2, 3}));
  EXPECT_EQ(AssociateByTime(estimate, std::vector<Time>{}, AssociationOptions{1.0}).matched(), 0u);
}

TEST(AssociationTest, SelectMatchedPairsThePoses) {
  Trajectory estimate(4);
  Trajectory reference(2);
  for (int i = 0; i < 4; ++i) {
    estimate[i].t = Time::FromNanoseconds(i * 10);
    estimate[i].p_world_body.x() = i;
  }
  reference[0].t = Time::FromNanoseconds(10);
  reference[1].t = Time::FromNanoseconds(30);
  reference[1].p_world_body.x() = 7.0;
  const Association a = AssociateByTime(estimate, reference, AssociationOptions{});
  const MatchedTrajectories m = SelectMatched(estimate, reference, a);
  ASSERT_EQ(m.estimate.size(), 2u);
  EXPECT_EQ(m.estimate[1].p_world_body.x(), 3.0);
  EXPECT_EQ(m.reference[1].p_world_body.x(), 7.0);
}

TEST(AssociationTest, NegativeToleranceIsInvalid) {
  EXPECT_FALSE(AssociationOptions{-1.0}.Validate().empty());
  EXPECT_TRUE(AssociationOptions{0.5}.Validate().empty());
}

}  // namespace
}  // namespace roamlab::eval
