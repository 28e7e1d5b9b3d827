// Issue 42: objects that were in the taught views near the route's end are not obstacles. A route
// that ends 0.5 m in front of a chair (there at teach time and still there) completes without a
// stop, because near the end the obstacle watch looks no farther than the route goes; with that
// limit off (an effectively infinite margin) the same run stops in front of the chair for good.
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

  // The same run without the limit: the watch sees the chair over the route's last metres.
  o.repeat.route_end_margin_m = 100.0;
  const RepeatRun unlimited = RepeatOnSimulator(scenario, taught, o);
  EXPECT_TRUE(EverBlocked(unlimited));
  EXPECT_FALSE(unlimited.success);
}

}  // namespace
}  // namespace mapless::eval
