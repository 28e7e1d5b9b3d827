#include "mapless/robot/sim_serve.h"

#include <chrono>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/io/lazy_libraries.h"
#include "mapless/robot/inbox.h"
#include "mapless/robot/sim_link.h"

namespace mapless::robot {

CameraMessage EncodeCamera(const cv::Mat& grey, const std::string& enc, cv::Size size) {
  cv::Mat frame = grey;
  if (size.area() > 0 && size != grey.size()) cv::resize(grey, frame, size, 0, 0, cv::INTER_LINEAR);
  CameraMessage msg;
  msg.encoding = enc;
  if (enc == "jpeg" || enc == "png") {
    msg.compressed = true;
    std::vector<uchar> bytes;
    io::lazy::ImEncode(enc == "png" ? ".png" : ".jpg", frame, &bytes, {});
    msg.data.assign(bytes.begin(), bytes.end());
    return msg;
  }
  cv::Mat packed;
  if (enc == "rgb8") {
    cv::cvtColor(frame, packed, cv::COLOR_GRAY2RGB);
  } else if (enc == "bgr8") {
    cv::cvtColor(frame, packed, cv::COLOR_GRAY2BGR);
  } else if (enc == "mono8") {
    packed = frame.isContinuous() ? frame : frame.clone();
  } else {
    packed = cv::Mat(frame.rows, frame.cols, CV_8UC2, cv::Scalar(128, 128));  // unknown
  }
  msg.width = static_cast<std::uint32_t>(packed.cols);
  msg.height = static_cast<std::uint32_t>(packed.rows);
  msg.step = static_cast<std::uint32_t>(packed.cols * packed.channels());
  msg.data.assign(packed.data, packed.data + packed.total() * packed.elemSize());
  return msg;
}

std::string ServedCameraTopic(const RobotFile& file, const std::string& encoding) {
  if (encoding != "jpeg" && encoding != "png") return file.Resolve(file.topics.image);
  return file.topics.compressed_image.empty() ? file.Resolve(file.topics.image) + "/compressed"
                                              : file.Resolve(file.topics.compressed_image);
}

void SimTransport::OnCommand(Twist2 t) {
  if (!std::isfinite(t.v_mps) || !std::isfinite(t.omega_radps)) t = Twist2{};
  std::lock_guard<std::mutex> lock(mutex_);
  last_ = t;
  last_at_ns_ = SteadyNs();
  ++commands_;
  cv_.notify_all();
}

void SimTransport::OnStatus(std::string_view text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("frame") || !j.contains("t_s") ||
      !j["t_s"].is_number())
    return;
  std::lock_guard<std::mutex> lock(mutex_);
  decided_ns_ = FromSeconds(j["t_s"].get<double>());
}

SimTransport::Wait SimTransport::WaitCommand(int seen, double timeout_s,
                                             const std::function<bool()>& interrupted,
                                             Twist2* command) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::unique_lock<std::mutex> lock(mutex_);
  while (commands_ <= seen) {
    if ((interrupted && interrupted()) || !ok() || !MethodPresent()) return Wait::kGone;
    if (std::chrono::steady_clock::now() > deadline) return Wait::kTimeout;
    cv_.wait_for(lock, std::chrono::milliseconds(5));
  }
  *command = last_;
  return Wait::kCommand;
}

int SimTransport::commands() {
  std::lock_guard<std::mutex> lock(mutex_);
  return commands_;
}

Twist2 SimTransport::Latest(double* age_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  *age_s = last_at_ns_ == 0 ? 1e9 : ToSeconds(SteadyNs() - last_at_ns_);
  return last_;
}

Timestamp SimTransport::DecidedAt() {
  std::lock_guard<std::mutex> lock(mutex_);
  return decided_ns_;
}

namespace {
nlohmann::json PoseJson(const Pose2& p) {
  return {{"x_m", p.x_m}, {"y_m", p.y_m}, {"theta_deg", RadToDeg(p.theta_rad)}};
}
}  // namespace

nlohmann::json ServeSummaryJson(const ServeSummary& s) {
  nlohmann::json j = {{"end", s.end},
                      {"frames", s.frames},
                      {"commands", s.commands},
                      {"resent", s.resent},
                      {"sim_time_s", s.sim_time_s},
                      {"collided", s.collided},
                      {"final", PoseJson(s.final_pose)}};
  if (s.collided) j["collision"] = s.collision;
  if (s.have_decided_pose) {
    j["decided"] = PoseJson(s.decided_pose);
    j["decided_x_m"] = s.decided_pose.x_m;
    j["decided_y_m"] = s.decided_pose.y_m;
  }
  return j;
}

ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const RobotFile& file,
                             const ServeOptions& options, SimTransport& transport) {
  const auto log = [&](const std::string& m) {
    if (options.log) options.log(m);
  };
  const auto interrupted = [&] { return options.interrupted && options.interrupted(); };
  ServeSummary summary;
  std::map<Timestamp, Pose2> truth_at;
  auto finish = [&](const std::string& why) {
    summary.end = why;
    summary.sim_time_s = ToSeconds(sim.now_ns());
    summary.final_pose = sim.robot(robot).pose();
    summary.collided = sim.collided(robot);
    const Timestamp decided = transport.DecidedAt();
    if (auto it = truth_at.find(decided); it != truth_at.end()) {
      summary.have_decided_pose = true;
      summary.decided_pose = it->second;
    }
    return summary;
  };
  auto step = [&](const Twist2& command) {
    sim.SetCommand(robot, command);
    sim.Advance(options.period_s);
    if (sim.collided(robot) && summary.collision.empty()) {
      summary.collision = SimulationStop(sim, robot, 1e18);
      log("sim serve: " + summary.collision);
    }
  };

  if (file.use_sim_time) {
    log("sim serve: lockstep in simulated time; waiting for a method to connect");
    while (!transport.MethodConnected()) {
      if (interrupted() || !transport.ok()) return finish("interrupted before a method connected");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    log("sim serve: a method connected");
    while (true) {
      const Pose2 truth = sim.robot(robot).pose();
      truth_at[sim.now_ns()] = truth;
      summary.path.push_back(truth);
      // Stamped with the simulated time: it is the ROS clock there, via /clock.
      const Timestamp stamp = sim.now_ns();
      const Pose2 odometry = sim.robot(robot).odometry();
      const cv::Mat grey = sim.Render(robot);
      const CameraMessage image = EncodeCamera(grey, options.encoding, options.size);
      transport.Publish(stamp, true, odometry, image);
      ++summary.frames;
      Twist2 command;
      while (true) {
        const SimTransport::Wait w =
            transport.WaitCommand(summary.commands, 1.0, interrupted, &command);
        if (w == SimTransport::Wait::kCommand) break;
        if (w == SimTransport::Wait::kGone)
          return finish(interrupted() ? "interrupted" : "the method left");
        transport.Publish(stamp, true, odometry, image);  // lost on the way, or a slow method
        ++summary.resent;
      }
      ++summary.commands;
      if (options.on_step) options.on_step({grey, stamp, odometry}, command, truth);
      step(command);
      if (ToSeconds(sim.now_ns()) > options.timeout_s) return finish("timeout");
    }
  }

  log("sim serve: real time at " + std::to_string(1.0 / options.period_s).substr(0, 5) + " Hz");
  auto next = std::chrono::steady_clock::now();
  while (true) {
    if (interrupted() || !transport.ok()) return finish("interrupted");
    const Pose2 truth = sim.robot(robot).pose();
    truth_at[sim.now_ns()] = truth;
    summary.path.push_back(truth);
    const Observation served{sim.Render(robot), transport.now_ns(), sim.robot(robot).odometry()};
    transport.Publish(served.t_ns, false, *served.odometry,
                      EncodeCamera(served.image, options.encoding, options.size));
    ++summary.frames;
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(options.period_s));
    std::this_thread::sleep_until(next);
    double age = 0.0;
    const Twist2 command = transport.Latest(&age);
    summary.commands = transport.commands();
    const Twist2 obeyed = age <= options.command_timeout_s ? command : Twist2{};
    if (options.on_step) options.on_step(served, obeyed, truth);
    step(obeyed);
    if (ToSeconds(sim.now_ns()) > options.timeout_s) return finish("timeout");
  }
}

}  // namespace mapless::robot
