// Issue 42: objects that were in the taught views near the route's end are not obstacles. A route
// that ends 0.5 m in front of a chair (there at teach time and still there) completes without a
// stop: near the end the obstacle watch looks no farther than the route goes, and the repeat
// tells it how far that is. (That the watch would stop for the same thing without the limit:
// ObstacleWatch.WhatStandsPastTheRoutesEndIsNotInTheWay. In this scenario, before the limit, 3 runs
// of 3 stopped for good 0.26 m before the end.)
#include <gtest/gtest.h>

#include <algorithm>

#include "mapless/eval/taught_once.h"
#include "mapless/eval/teach_repeat.h"

namespace mapless::eval {
namespace {

bool EverBlocked(const RepeatRun& run) {
  return std::any_of(run.steps.begin(), run.steps.end(), [](const navigation::RepeatStep& s) {
    return s.status == navigation::RepeatStatus::kBlocked;
  });
}

TEST(RouteEnd, AChairPastTheEndOfTheRouteDoesNotStopTheRepeat) {
  const auto& [scenario, taught] = TaughtOnce("end_before_chair");
  RepeatRunOptions o;
  o.seed = 1;
  const RepeatRun run = RepeatOnSimulator(scenario, taught, o);
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(EverBlocked(run));
  EXPECT_LE(run.final_error_m, 0.2);
}

}  // namespace
}  // namespace mapless::eval
