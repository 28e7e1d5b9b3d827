// `mapless bench`: the options, then the benches of src/mapless/bench (bench.h) and their table.
#include "builtin_middlewares.h"
#include "cli_common.h"
#include "mapless/bench/bench.h"

namespace mapless::app {

void AddBenchCommand(CLI::App* app) {
  using Args = bench::BenchRequest;
  auto args = std::make_shared<Args>();
  CLI::App* bench = app->add_subcommand(
      "bench",
      "Per-stage medians (ms, one thread, 320x240) with OpenCV references from the same run");
  bench->add_flag("--json", args->json, "Print one JSON object instead of a table");
  bench->add_option("--repeats", args->repeats, "Timed calls per stage")
      ->capture_default_str()
      ->check(CLI::Range(3, 100000));
  bench->add_option("--scenario", args->scenario,
                    "Render views of this scenario only (default: narrow_room_sharp_turn, "
                    "outdoor_70m and office_aliasing, 12 views along each taught path)");
  bench->add_option("--size", args->size,
                    "Frame size of every stage, WxH (default 320x240; e.g. 640x480 for a larger "
                    "camera; the JSON keys keep their 320x240)");
  bench->add_flag("--ros1", args->ros1,
                  "Also the ROS 1 adapter's latency, frame received to command published "
                  "(starts a ROS master on loopback)");
  bench->add_flag("--ros2", args->ros2,
                  "Also the ROS 2 (DDS) adapter's latency, frame received to command published "
                  "(a DDS domain of its own on loopback)");
  bench->add_flag("--fleet", args->fleet,
                  "Also the fleet link on loopback: record latency, leader's write to follower's "
                  "receive, and a late follower's catch-up on a 1000-record route");
  bench->add_flag("--live-view", args->live, "Also the live view: loop with 0/3 clients, latency");
  bench->add_flag(
      "--links-only", args->links_only,
      "Only the link rows (--ros1, --ros2, --fleet, --live-view), not the method stages");
  bench->callback([args] { bench::RunBench(*args, BuiltinMiddlewares()); });
}

}  // namespace mapless::app
