// The ROS 2 safety tests' probe (issue 18), the DDS twin of tests/ros1/safety_probe.cc: reads
// cmd_vel (rt/cmd_vel), waits until the robot is being driven (N non-zero commands), then does one
// thing and measures the time until the method publishes a zero Twist:
//   kill PID    SIGKILL to the camera publisher (the watchdog)
//   int PID     SIGINT to the method (Ctrl-C)
//   estop       true on /mapless/estop, held 1.2 s (commands meanwhile at most MAX_STOP_PER_S a
//               second); then false, and the robot must be driven again within 2 s
//   listen      (no action, NONZERO 0) the first command within LIMIT_S must be a zero Twist
//               (teleop ending before any frame: tests/robot_link/teleop.sh); with
//               SAFETY_PROBE_READY=FILE it writes FILE once a publisher of cmd_vel is matched
//               (so the test acts on a connected robot link, not after a guessed delay)
//   topics      (no action) the status topic carries one JSON object per frame naming the method,
//               and the debug image topic bgr8 pictures at least 320 wide
// Prints one JSON line; exit 0 when the zero came within the limit, 1 otherwise.
//   safety_probe kill|int|estop|listen|topics PID LIMIT_S [NONZERO_COMMANDS [MAX_STOP_PER_S]]
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

#include "mapless/ros2/dds.h"
#include "mapless/ros2/messages.h"

namespace {

// Writes the ready file (SAFETY_PROBE_READY) atomically; true when written.
bool WriteReadyFile(const char* path) {
  const std::string tmp = std::string(path) + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "w");
  if (f == nullptr) return false;
  std::fputs("matched\n", f);
  return std::fclose(f) == 0 && std::rename(tmp.c_str(), path) == 0;
}

using Clock = std::chrono::steady_clock;
using namespace mapless::ros2;  // NOLINT: a test program

std::mutex g_mutex;
int g_nonzero = 0;
bool g_acted = false;
Clock::time_point g_act_time;
bool g_after = false;
bool g_after_zero = false;
double g_after_s = 0.0;
bool g_released = false;
int g_nonzero_after_release = 0;
int g_nonzero_during_stop = 0;  // must stay 0 while the e-stop is on
int g_during_stop = 0;          // every command while the e-stop is on (its rate is bounded)
int g_statuses = 0, g_good_statuses = 0, g_images = 0, g_good_images = 0;

void OnTwist(dds_entity_t reader, void*) {
  TakeAll<geometry_msgs_msg_dds__Twist_>(reader, [](const geometry_msgs_msg_dds__Twist_& t) {
    std::lock_guard<std::mutex> lock(g_mutex);
    const bool zero = t.linear.x == 0.0 && t.angular.z == 0.0;
    if (!g_acted) {
      if (!zero) ++g_nonzero;
      return;
    }
    if (g_released && !zero) ++g_nonzero_after_release;
    if (!g_released && !zero) ++g_nonzero_during_stop;
    if (!g_released) ++g_during_stop;
    if (g_after) return;
    g_after = true;
    g_after_zero = zero;
    g_after_s = std::chrono::duration<double>(Clock::now() - g_act_time).count();
  });
}

void OnStatus(dds_entity_t reader, void*) {
  TakeAll<std_msgs_msg_dds__String_>(reader, [](const std_msgs_msg_dds__String_& s) {
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g_statuses;
    const std::string t = s.data ? s.data : "";
    if (t.size() > 2 && t.front() == '{' && t.back() == '}' &&
        t.find("\"method\":\"repeat\"") != std::string::npos)
      ++g_good_statuses;
  });
}

void OnDebug(dds_entity_t reader, void*) {
  TakeAll<sensor_msgs_msg_dds__Image_>(reader, [](const sensor_msgs_msg_dds__Image_& m) {
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g_images;
    if (m.encoding != nullptr && std::string(m.encoding) == "bgr8" && m.width >= 320 &&
        m.data._length == static_cast<std::size_t>(m.step) * m.height)
      ++g_good_images;
  });
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr,
                 "usage: safety_probe kill|int|estop|listen|topics PID LIMIT_S [NONZERO]\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int pid = std::atoi(argv[2]);
  const double limit = std::atof(argv[3]);
  const int wanted = argc > 4 ? std::atoi(argv[4]) : 10;
  // estop: commands per second allowed while it is held (the camera rate plus the watchdog).
  const double max_stop_hz = argc > 5 ? std::atof(argv[5]) : 15.0;
  double stop_hz = 0.0;
  dds_listener_t* listener = dds_create_listener(nullptr);
  dds_lset_data_available(listener, OnTwist);
  const dds_entity_t cmd_reader = MakeReader(&geometry_msgs_msg_dds__Twist__desc, "/cmd_vel",
                                             "geometry_msgs/msg/Twist", Qos::kDefault, listener);
  const dds_entity_t estop = MakeWriter(&std_msgs_msg_dds__Bool__desc, "/mapless/estop",
                                        "std_msgs/msg/Bool", Qos::kDefault);
  if (mode == "topics") {
    dds_lset_data_available(listener, OnStatus);
    MakeReader(&std_msgs_msg_dds__String__desc, "/mapless/status", "std_msgs/msg/String",
               Qos::kDefault, listener);
    dds_lset_data_available(listener, OnDebug);
    MakeReader(&sensor_msgs_msg_dds__Image__desc, "/mapless/debug_image", "sensor_msgs/msg/Image",
               Qos::kSensorData, listener);
    const auto until = Clock::now() + std::chrono::seconds(20);
    while (Clock::now() < until) {
      {
        std::lock_guard<std::mutex> lock(g_mutex);
        if (g_good_statuses >= 10 && g_good_images >= 5) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::lock_guard<std::mutex> lock(g_mutex);
    std::printf(
        "{\"mode\": \"topics\", \"statuses\": %d, \"good_statuses\": %d, "
        "\"debug_images\": %d, \"good_debug_images\": %d}\n",
        g_statuses, g_good_statuses, g_images, g_good_images);
    std::fflush(stdout);
    const bool ok = g_good_statuses >= 10 && g_good_images >= 5 && g_good_statuses == g_statuses;
    std::_Exit(ok ? 0 : 1);  // no DDS teardown while listeners may run
  }
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (true) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_nonzero >= wanted) {
        g_acted = true;
        g_act_time = Clock::now();
        if (mode == "kill") {
          kill(pid, SIGKILL);
        } else if (mode == "int") {
          kill(pid, SIGINT);
        } else if (mode == "listen") {
          // no action: the first command, whenever it comes within LIMIT_S, must be a zero
        } else {
          WriteBool(estop, true);
        }
        break;
      }
    }
    if (Clock::now() > deadline) {
      std::printf("{\"error\": \"the robot was never driven (%d non-zero commands)\"}\n",
                  g_nonzero);
      std::fflush(stdout);
      std::_Exit(1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const auto wait_until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(mode == "listen" ? limit : 3.0));
  const char* ready_file = std::getenv("SAFETY_PROBE_READY");
  bool ready = false;
  while (Clock::now() < wait_until) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_after) break;
    }
    dds_subscription_matched_status_t matched{};
    if (ready_file != nullptr && !ready &&
        dds_get_subscription_matched_status(cmd_reader, &matched) == DDS_RETCODE_OK &&
        matched.current_count > 0)
      ready = WriteReadyFile(ready_file);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  bool resumed = true;
  if (mode == "estop") {
    // Held for a second: the commands meanwhile are counted (zero Twists at most at the camera
    // rate plus the watchdog's, never as fast as the loop turns).
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    int held_from = 0;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      held_from = g_during_stop;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      g_released = true;
      stop_hz = g_during_stop - held_from;
      if (g_nonzero_during_stop > 0) resumed = false;
    }
    WriteBool(estop, false);
    std::this_thread::sleep_for(std::chrono::seconds(2));
    std::lock_guard<std::mutex> lock(g_mutex);
    resumed = resumed && g_nonzero_after_release > 0;
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_after) {
    std::printf("{\"mode\": \"%s\", \"error\": \"no command within 3 s\"}\n", mode.c_str());
    std::fflush(stdout);
    std::_Exit(1);
  }
  std::printf(
      "{\"mode\": \"%s\", \"zero\": %s, \"after_s\": %.4f, \"limit_s\": %.3f, "
      "\"stop_per_s\": %.0f%s}\n",
      mode.c_str(), g_after_zero ? "true" : "false", g_after_s, limit, stop_hz,
      mode == "estop" ? (resumed ? ", \"resumed\": true" : ", \"resumed\": false") : "");
  std::fflush(stdout);
  std::_Exit(g_after_zero && g_after_s <= limit && resumed && stop_hz <= max_stop_hz ? 0 : 1);
}
