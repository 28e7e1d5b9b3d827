#include "mapless/localization/markov.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mapless/core/check.h"
#include "mapless/localization/initial.h"
#include "mapless/localization/nearest.h"

namespace mapless::localization {
namespace {

// A route of `n` places with aliasing: the appearance repeats every `period` places (identical
// doors) up to a small per-place signature, so that a noisy image can hardly tell place i from
// place i + period.
Eigen::MatrixXf AliasedRoute(int n, int period, float signature = 0.0F) {
  Eigen::MatrixXf p(3, n);
  std::uint32_t state = 12345;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * (i % period) / period;
    state = state * 1664525U + 1013904223U;
    p(0, i) = static_cast<float>(std::cos(a));
    p(1, i) = static_cast<float>(std::sin(a));
    p(2, i) = signature * (static_cast<float>(state >> 8) / 16777216.0F - 0.5F);
  }
  return p;
}

// A route whose place i looks like the value i: every place is distinct.
Eigen::MatrixXf LinearRoute(int n) {
  Eigen::MatrixXf route(1, n);
  for (int i = 0; i < n; ++i) route(0, i) = static_cast<float>(i);
  return route;
}

// An image that looks like place `place` of a LinearRoute.
Eigen::VectorXf LooksLike(float place) {
  Eigen::VectorXf image(1);
  image << place;
  return image;
}

TEST(NearestProjection, FindsTheClosestColumn) {
  Eigen::MatrixXf p(1, 4);
  p << 0.0F, 1.0F, 2.0F, 3.0F;
  Eigen::VectorXf q(1);
  q << 2.2F;
  const auto nn = NearestProjections(p, q, 2);
  ASSERT_EQ(nn.size(), 2U);
  EXPECT_EQ(nn[0].index, 2);
  EXPECT_EQ(nn[1].index, 3);
  EXPECT_NEAR(nn[0].distance, 0.2F, 1e-5F);
}

// Places with several images (learned views, issue 45): a place is as near as its nearest image;
// with one image per place in order it is NearestProjections, and Markov over places is the
// plain update bit for bit.
TEST(NearestPlaces, APlaceIsAsNearAsItsNearestImage) {
  Eigen::MatrixXf p(1, 6);
  p << 0.0F, 1.0F, 2.0F, 3.0F, 7.1F, 3.05F;  // columns 4 and 5: views of places 1 and 0
  const std::vector<int> place{0, 1, 2, 3, 1, 0};
  const auto nn = NearestPlaces(p, place, 4, LooksLike(7.0F), 2);
  ASSERT_EQ(nn.size(), 2U);
  EXPECT_EQ(nn[0].index, 1);
  EXPECT_EQ(nn[0].column, 4);
  EXPECT_NEAR(nn[0].distance, 0.1F, 1e-5F);
  EXPECT_EQ(nn[1].index, 0);  // by its view at 3.05, ahead of place 3 (4.0 away)
  EXPECT_EQ(nn[1].column, 5);
  EXPECT_THROW(NearestPlaces(p, {0, 1}, 4, LooksLike(0.0F), 2), InputError);
  EXPECT_THROW(NearestPlaces(p, {0, 1, 2, 3, 9, 0}, 4, LooksLike(0.0F), 2), InputError);

  const Eigen::MatrixXf route = LinearRoute(30);
  std::vector<int> identity(30);
  for (int i = 0; i < 30; ++i) identity[static_cast<std::size_t>(i)] = i;
  MarkovLocalizer plain;
  MarkovLocalizer places;
  for (int t = 0; t < 25; ++t) {
    const Eigen::VectorXf q = LooksLike(static_cast<float>(t) + 0.3F * std::sin(t));
    const Localization a = plain.Update(route, q, 1.0);
    const Localization b = places.Update(route, identity, 30, q, 1.0);
    EXPECT_EQ(a.index, b.index);
    EXPECT_EQ((plain.belief() - places.belief()).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(MarkovLocalizer, TracksThroughVisualAliasingWhereNearestProjectionIsAmbiguous) {
  const int n = 120;
  const int period = 15;
  const Eigen::MatrixXf route = AliasedRoute(n, period, 0.2F);
  MarkovLocalizer markov;
  markov.ResetAt(n, 0.0, 2.0);
  int markov_correct = 0;
  int nn_correct = 0;
  std::uint32_t state = 777;
  const auto noise = [&] {
    state = state * 1664525U + 1013904223U;
    return 0.3F * (static_cast<float>(state >> 8) / 16777216.0F - 0.5F);
  };
  for (int t = 1; t < n; ++t) {
    // Observation: the true place's appearance plus noise larger than the per-place signature.
    Eigen::VectorXf z = route.col(t);
    for (int c = 0; c < 3; ++c) z(c) += noise();
    const Localization loc = markov.Update(route, z, 1.0);
    markov_correct += std::abs(loc.index - t) <= 1;
    nn_correct += std::abs(NearestProjection(route, z).index - t) <= 1;
    EXPECT_EQ(loc.status, LocalizationStatus::kTracking);
  }
  EXPECT_GE(markov_correct, n - 3);
  EXPECT_LT(nn_correct, n / 2);
}

TEST(MarkovLocalizer, ReportsLostWhenObservationsContradictTheMotion) {
  const int n = 100;
  Eigen::MatrixXf route(1, n);
  for (int i = 0; i < n; ++i) route(0, i) = static_cast<float>(i);
  MarkovOptions options;
  options.lost_after_updates = 3;
  MarkovLocalizer markov(options);
  markov.ResetAt(n, 10.0, 1.0);
  Localization loc;
  // The images say the robot jumps around the route at random.
  const int jumps[] = {80, 20, 60, 5, 95, 40, 70, 30};
  int lost = 0;
  for (const int j : jumps) {
    Eigen::VectorXf z(1);
    z << static_cast<float>(j);
    loc = markov.Update(route, z, 0.0);
    lost += loc.status == LocalizationStatus::kLost;
  }
  EXPECT_GT(lost, 0);
}

TEST(MarkovLocalizer, FollowsARouteThatGrowsWhileItIsUsed) {
  const Eigen::MatrixXf full = AliasedRoute(60, 60);
  MarkovLocalizer markov;
  markov.ResetAt(10, 0.0, 1.0);
  Localization loc;
  for (int t = 1; t < 50; ++t) {
    const int known = std::min(60, 10 + t);  // the leader adds one image per step
    loc = markov.Update(full.leftCols(known), full.col(t), 1.0);
    EXPECT_LE(std::abs(loc.index - t), 1) << t;
  }
  EXPECT_THROW(markov.Update(full.leftCols(5), full.col(0), 0.0), InputError);
}

// The robot stands at place 60 while for a long time the images look like place 20 (say, an
// aliased twin seen first); then the images show place 60. Without mixing, the belief far from the
// peak has underflowed to zero and never comes back; with 1% uniform mixing it moves to place 60.
TEST(MarkovLocalizer, UniformMixingLetsAWrongBeliefGiveWay) {
  const int n = 100;
  const Eigen::MatrixXf route = LinearRoute(n);
  const Eigen::VectorXf twin = LooksLike(20.0F);
  const Eigen::VectorXf truth = LooksLike(60.0F);
  for (const double mixing : {0.0, 0.01}) {
    MarkovOptions options;
    options.uniform_mixing = mixing;
    MarkovLocalizer markov(options);
    markov.ResetAt(n, 20.0, 1.0);
    for (int t = 0; t < 300; ++t) markov.Update(route, twin, 0.0);
    Localization loc;
    for (int t = 0; t < 30; ++t) loc = markov.Update(route, truth, 0.0);
    if (mixing == 0.0) {
      EXPECT_EQ(loc.index, 20);
    } else {
      EXPECT_EQ(loc.index, 60);
    }
  }
}

// The images look like place 25, an aliased twin of where the robot is. Unlimited, the belief
// (with 1% uniform mixing: it may go anywhere) moves to 25 after `updates` updates from a belief
// around `start`; limited to [min_index, max_index], it stays inside and holds no mass outside.
void ExpectLimitsHold(double start, int min_index, int max_index) {
  const int n = 60;
  const Eigen::MatrixXf route = LinearRoute(n);
  const Eigen::VectorXf twin = LooksLike(25.0F);
  MarkovOptions options;
  options.uniform_mixing = 0.01;
  MarkovLocalizer unlimited(options);
  MarkovLocalizer limited(options);
  unlimited.ResetAt(n, start, 2.0);
  limited.ResetAt(n, start, 2.0);
  limited.set_index_limits(min_index, max_index);
  Localization free_loc;
  Localization loc;
  for (int t = 0; t < 20; ++t) {
    free_loc = unlimited.Update(route, twin, 0.0);
    loc = limited.Update(route, twin, 0.0);
  }
  EXPECT_EQ(free_loc.index, 25);
  const int lo = std::max(min_index, 0);
  const int hi = max_index < 0 ? n - 1 : max_index;
  EXPECT_GE(loc.index, lo);
  EXPECT_LE(loc.index, hi);
  EXPECT_EQ(limited.belief().head(lo).sum() + limited.belief().tail(n - 1 - hi).sum(), 0.0);
  EXPECT_NEAR(limited.belief().sum(), 1.0, 1e-9);
  // Lifted, the limits no longer hold the belief.
  limited.set_index_limits(-1, -1);
  for (int t = 0; t < 20; ++t) loc = limited.Update(route, twin, 0.0);
  EXPECT_EQ(loc.index, 25);
}

// At place 10, images like place 25 further along: a robot that cannot have got past place 14
// stays at or before it.
TEST(MarkovLocalizer, AMaximumIndexKeepsTheBeliefFromRunningAhead) {
  ExpectLimitsHold(10.0, -1, 14);
}

// At place 40, images like place 25 behind: a robot that cannot be before place 36 stays there.
TEST(MarkovLocalizer, AMinimumIndexKeepsTheBeliefFromFallingBack) {
  ExpectLimitsHold(40.0, 36, -1);
}

// Dead reckoning (the follower carrying on where the route images no longer fit): the belief
// moves with the advance alone, spreads, stays within the limits and is never reported lost,
// while the same images as observations would have pulled it back and declared it lost.
TEST(MarkovLocalizer, PredictionAloneMovesTheBeliefByTheAdvanceAndNeverLosesIt) {
  const int n = 100;
  const Eigen::MatrixXf route = LinearRoute(n);
  MarkovOptions options;
  options.lost_after_updates = 3;
  MarkovLocalizer reckoning(options);
  MarkovLocalizer observing(options);
  reckoning.ResetAt(n, 10.0, 1.0);
  observing.ResetAt(n, 10.0, 1.0);
  Localization by_advance;
  Localization by_images;
  int lost = 0;
  for (int t = 0; t < 10; ++t) {
    by_advance = reckoning.Predict(n, 2.0);
    by_images = observing.Update(route, LooksLike(10.0F), 2.0);  // the view of place 10 stays
    lost += by_images.status == LocalizationStatus::kLost;
  }
  EXPECT_EQ(by_advance.status, LocalizationStatus::kTracking);
  EXPECT_NEAR(by_advance.index, 30, 1);
  EXPECT_LT(by_advance.probability, 0.5);            // spread by the motion model
  EXPECT_LT(by_images.index, by_advance.index - 3);  // held back by the view of place 10
  EXPECT_GT(lost, 0);
  // The limits hold too.
  reckoning.set_index_limits(-1, 32);
  for (int t = 0; t < 5; ++t) by_advance = reckoning.Predict(n, 2.0);
  EXPECT_LE(by_advance.index, 32);
  EXPECT_EQ(reckoning.belief().tail(n - 33).sum(), 0.0);
  EXPECT_NEAR(reckoning.belief().sum(), 1.0, 1e-9);
}

TEST(MarkovOptions, RejectsBadValuesNamingTheField) {
  MarkovOptions options;
  options.kernels = 0;
  try {
    options.Validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("MarkovOptions.kernels = 0"), std::string::npos);
  }
}

TEST(InitialLocalization, ChoosesTheTightestLargeCluster) {
  // Images around place 9 localize near 9, a few aliased ones near 24 and one stray at 40.
  const std::vector<int> localizations = {9, 10, 24, 8, 9, 25, 10, 40, 9, 23, 11, 9};
  const InitialLocalization init = LocalizeByClustering(localizations, {});
  ASSERT_TRUE(init.ok) << init.reason;
  EXPECT_EQ(init.index, 9);
  EXPECT_EQ(init.clusters.size(), 3U);
}

TEST(InitialLocalization, FailsWithoutAConsistentCluster) {
  const InitialLocalization init = LocalizeByClustering({1, 20, 40, 60, 80}, {});
  EXPECT_FALSE(init.ok);
  EXPECT_FALSE(init.reason.empty());
}

}  // namespace
}  // namespace mapless::localization
