// The watchdog test's probe (issue 17): subscribes cmd_vel, waits until the robot is being driven
// (N non-zero commands), kills the camera publisher (SIGKILL, the pid given), and measures the time
// until the method publishes a zero Twist. Prints one JSON line; exit 0 when the zero came within
// the limit, 1 when it came late, was not zero, or never came.
//   watchdog_probe PID LIMIT_S [NONZERO_COMMANDS]
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

namespace {

using Clock = std::chrono::steady_clock;
std::mutex g_mutex;
int g_nonzero = 0;
bool g_killed = false;
Clock::time_point g_kill_time;
bool g_after = false;
bool g_after_zero = false;
double g_after_s = 0.0;

void OnTwist(const geometry_msgs::TwistConstPtr& msg) {
  std::lock_guard<std::mutex> lock(g_mutex);
  const bool zero = msg->linear.x == 0.0 && msg->angular.z == 0.0;
  if (!g_killed) {
    if (!zero) ++g_nonzero;
    return;
  }
  if (g_after) return;
  g_after = true;
  g_after_zero = zero;
  g_after_s = std::chrono::duration<double>(Clock::now() - g_kill_time).count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: watchdog_probe PID LIMIT_S [NONZERO_COMMANDS]\n");
    return 2;
  }
  const int pid = std::atoi(argv[1]);
  const double limit = std::atof(argv[2]);
  const int wanted = argc > 3 ? std::atoi(argv[3]) : 10;
  ros::init(argc, argv, "watchdog_probe", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe("/cmd_vel", 100, OnTwist, ros::TransportHints().tcpNoDelay());
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (true) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_nonzero >= wanted) {
        g_killed = true;
        g_kill_time = Clock::now();
        kill(pid, SIGKILL);
        break;
      }
    }
    if (Clock::now() > deadline) {
      std::printf("{\"error\": \"the robot was never driven (%d non-zero commands)\"}\n", g_nonzero);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const auto wait_until = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < wait_until) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_after) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_after) {
    std::printf("{\"error\": \"no command within 3 s after the camera was killed\"}\n");
    return 1;
  }
  std::printf("{\"zero\": %s, \"after_kill_s\": %.4f, \"limit_s\": %.3f}\n",
              g_after_zero ? "true" : "false", g_after_s, limit);
  return g_after_zero && g_after_s <= limit ? 0 : 1;
}
