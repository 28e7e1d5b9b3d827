// The safety tests' probe (issue 17): subscribes cmd_vel, waits until the robot is being driven
// (N non-zero commands), then does one thing and measures the time until the method publishes a
// zero Twist:
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
// Prints one JSON line; exit 0 when the zero came within the limit, 1 when it came late, was not
// zero, or never came (or, for estop, driving did not resume).
//   safety_probe kill|int|estop PID LIMIT_S [NONZERO_COMMANDS [MAX_STOP_PER_S]]
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <signal.h>
#include <std_msgs/Bool.h>
#include <std_msgs/String.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

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
std::mutex g_mutex;
int g_nonzero = 0;
bool g_killed = false;
Clock::time_point g_kill_time;
bool g_after = false;
bool g_after_zero = false;
double g_after_s = 0.0;
bool g_released = false;
int g_nonzero_after_release = 0;
int g_nonzero_during_stop = 0;  // must stay 0 while the e-stop is on
int g_during_stop = 0;          // every command while the e-stop is on (its rate is bounded)

void OnTwist(const geometry_msgs::TwistConstPtr& msg) {
  std::lock_guard<std::mutex> lock(g_mutex);
  const bool zero = msg->linear.x == 0.0 && msg->angular.z == 0.0;
  if (!g_killed) {
    if (!zero) ++g_nonzero;
    return;
  }
  if (g_released && !zero) ++g_nonzero_after_release;
  if (!g_released && !zero) ++g_nonzero_during_stop;
  if (!g_released) ++g_during_stop;
  if (g_after) return;
  g_after = true;
  g_after_zero = zero;
  g_after_s = std::chrono::duration<double>(Clock::now() - g_kill_time).count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: safety_probe kill|int|estop PID LIMIT_S [NONZERO_COMMANDS]\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int pid = std::atoi(argv[2]);
  const double limit = std::atof(argv[3]);
  const int wanted = argc > 4 ? std::atoi(argv[4]) : 10;
  // estop: commands per second allowed while it is held (the camera rate plus the watchdog).
  const double max_stop_hz = argc > 5 ? std::atof(argv[5]) : 15.0;
  double stop_hz = 0.0;
  ros::init(argc, argv, "safety_probe", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe("/cmd_vel", 100, OnTwist, ros::TransportHints().tcpNoDelay());
  ros::Publisher estop = nh.advertise<std_msgs::Bool>("/mapless/estop", 1, true);
  if (mode == "topics") {
    std::mutex m;
    int statuses = 0, good_statuses = 0, images = 0, good_images = 0;
    ros::Subscriber status = nh.subscribe<std_msgs::String>(
        "/mapless/status", 100, [&](const std_msgs::StringConstPtr& msg) {
          std::lock_guard<std::mutex> lock(m);
          ++statuses;
          const std::string& t = msg->data;
          if (t.size() > 2 && t.front() == '{' && t.back() == '}' &&
              t.find("\"method\":\"repeat\"") != std::string::npos)
            ++good_statuses;
        });
    ros::Subscriber debug = nh.subscribe<sensor_msgs::Image>(
        "/mapless/debug_image", 10, [&](const sensor_msgs::ImageConstPtr& msg) {
          std::lock_guard<std::mutex> lock(m);
          ++images;
          if (msg->encoding == "bgr8" && msg->width >= 320 &&
              msg->data.size() == static_cast<std::size_t>(msg->step) * msg->height) {
            ++good_images;
            // For a person to look at: MAPLESS_DEBUG_IMAGE_OUT=FILE.ppm keeps the 20th picture.
            const char* out = std::getenv("MAPLESS_DEBUG_IMAGE_OUT");
            if (out != nullptr && good_images == 20) {
              if (FILE* f = std::fopen(out, "wb")) {
                std::fprintf(f, "P6\n%u %u\n255\n", msg->width, msg->height);
                for (std::size_t i = 0; i + 2 < msg->data.size(); i += 3) {
                  const unsigned char rgb[3] = {msg->data[i + 2], msg->data[i + 1], msg->data[i]};
                  std::fwrite(rgb, 1, 3, f);
                }
                std::fclose(f);
              }
            }
          }
        });
    ros::AsyncSpinner spinner(1);
    spinner.start();
    const auto until = Clock::now() + std::chrono::seconds(20);
    while (Clock::now() < until) {
      {
        std::lock_guard<std::mutex> lock(m);
        if (good_statuses >= 10 && good_images >= (std::getenv("MAPLESS_DEBUG_IMAGE_OUT") ? 25 : 5))
          break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::lock_guard<std::mutex> lock(m);
    std::printf(
        "{\"mode\": \"topics\", \"statuses\": %d, \"good_statuses\": %d, "
        "\"debug_images\": %d, \"good_debug_images\": %d}\n",
        statuses, good_statuses, images, good_images);
    (void)pid;
    (void)limit;
    (void)wanted;
    return good_statuses >= 10 && good_images >= 5 && good_statuses == statuses ? 0 : 1;
  }
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (true) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_nonzero >= wanted) {
        g_killed = true;
        g_kill_time = Clock::now();
        if (mode == "kill") {
          kill(pid, SIGKILL);
        } else if (mode == "int") {
          kill(pid, SIGINT);
        } else if (mode == "listen") {
          // no action: the first command, whenever it comes within LIMIT_S, must be a zero
        } else {
          std_msgs::Bool on;
          on.data = true;
          estop.publish(on);
        }
        break;
      }
    }
    if (Clock::now() > deadline) {
      std::printf("{\"error\": \"the robot was never driven (%d non-zero commands)\"}\n",
                  g_nonzero);
      return 1;
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
    if (ready_file != nullptr && !ready && sub.getNumPublishers() > 0)
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
      // Stopped all the while: every command since the e-stop was zero.
      if (g_nonzero_during_stop > 0) resumed = false;
    }
    std_msgs::Bool off;
    off.data = false;
    estop.publish(off);
    std::this_thread::sleep_for(std::chrono::seconds(2));
    std::lock_guard<std::mutex> lock(g_mutex);
    resumed = resumed && g_nonzero_after_release > 0;
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_after) {
    std::printf("{\"mode\": \"%s\", \"error\": \"no command within 3 s\"}\n", mode.c_str());
    return 1;
  }
  std::printf(
      "{\"mode\": \"%s\", \"zero\": %s, \"after_s\": %.4f, \"limit_s\": %.3f, "
      "\"stop_per_s\": %.0f%s}\n",
      mode.c_str(), g_after_zero ? "true" : "false", g_after_s, limit, stop_hz,
      mode == "estop" ? (resumed ? ", \"resumed\": true" : ", \"resumed\": false") : "");
  return g_after_zero && g_after_s <= limit && resumed && stop_hz <= max_stop_hz ? 0 : 1;
}
