#include "mapless/sim/simulation.h"

#include <cmath>

#include "mapless/core/check.h"
#include "mapless/io/yaml_reader.h"
#include "mapless/sim/driver.h"

namespace mapless::sim {

void SimulationOptions::Validate() const {
  MAPLESS_CHECK(physics_dt_s >= 1e-4 && physics_dt_s <= 0.1,
                "SimulationOptions.physics_dt_s = " << physics_dt_s << "; must be in [1e-4, 0.1]");
  MAPLESS_CHECK(
      robot_body_height_m > 0.0 && robot_body_height_m <= 10.0,
      "SimulationOptions.robot_body_height_m = " << robot_body_height_m << "; must be in (0, 10]");
  MAPLESS_CHECK(robot_body_height_m > 0.0, "SimulationOptions.robot_body_height_m = "
                                               << robot_body_height_m << "; must be > 0");
  render.Validate();
}

void DriveOptions::Validate() const {
  MAPLESS_CHECK(timeout_factor >= 1.0 && timeout_factor <= 100.0,
                "DriveOptions.timeout_factor = " << timeout_factor << "; must be in [1, 100]");
  sim.Validate();
}

Simulation::Simulation(const World& world, CameraSpec camera, SimulationOptions options,
                       std::uint64_t seed)
    : all_objects_(world), camera_(std::move(camera)), options_(options), seed_(seed) {
  options_.Validate();
  camera_.Validate();
  all_objects_.Validate();
  changes_s_ = ChangeTimes(all_objects_);
  world_ = changes_s_.empty() ? all_objects_ : WorldAt(all_objects_, 0.0);
}

void Simulation::UpdateTimedObjects() {
  if (next_change_ >= changes_s_.size() || ToSeconds(t_ns_) < changes_s_[next_change_]) return;
  while (next_change_ < changes_s_.size() && ToSeconds(t_ns_) >= changes_s_[next_change_])
    ++next_change_;
  world_ = WorldAt(all_objects_, ToSeconds(t_ns_));
  renderer_.reset();  // rebuilt (with its textures) at the next render
}

const Renderer& Simulation::renderer() const {
  if (!renderer_) renderer_ = std::make_unique<Renderer>(world_, options_.render);
  return *renderer_;
}

void Simulation::PlaceRobot(int robot, const Pose2& pose) {
  const auto i = static_cast<std::size_t>(robot);
  robots_.at(i).Reset(pose);
  stopped_.at(i) = false;
}

int Simulation::AddRobot(const Pose2& start, const RobotOptions& options) {
  const int index = robot_count();
  robots_.emplace_back(start, options,
                       Rng::Derive(seed_, 1000 + static_cast<std::uint64_t>(index)).NextU64());
  frames_.push_back(0);
  stopped_.push_back(false);
  TextureSpec body;
  body.type = TextureType::kBlobs;
  body.seed = 7000 + static_cast<std::uint64_t>(index);
  body.texel_m = 0.004;
  body_textures_.push_back(GenerateTexture(body));
  return index;
}

void Simulation::SetCommand(int robot, const Twist2& command) {
  const auto i = static_cast<std::size_t>(robot);
  if (stopped_.at(i)) return;
  robots_.at(i).SetCommand(command);
}

bool Simulation::collided(int robot) const {
  for (const Collision& c : collisions_) {
    if (c.robot == robot) return true;
  }
  return false;
}

void Simulation::Advance(double dt_s) {
  MAPLESS_CHECK(dt_s >= 0.0 && dt_s <= 60.0,
                "Simulation::Advance: dt = " << dt_s << " s; must be in [0, 60]");
  const int steps = std::max(1, static_cast<int>(std::lround(dt_s / options_.physics_dt_s)));
  for (int k = 0; k < steps; ++k) {
    for (std::size_t i = 0; i < robots_.size(); ++i) {
      if (!stopped_[i]) robots_[i].Step(options_.physics_dt_s);
    }
    t_ns_ += FromSeconds(options_.physics_dt_s);
    UpdateTimedObjects();
    CheckCollisions();
  }
}

void Simulation::CheckCollisions() {
  for (std::size_t i = 0; i < robots_.size(); ++i) {
    if (stopped_[i]) continue;
    const Pose2& p = robots_[i].pose();
    const double r = robots_[i].options().radius_m;
    std::string with;
    if (ClearanceTo(world_, p.x_m, p.y_m) < r) with = "obstacle";
    for (std::size_t j = 0; j < robots_.size() && with.empty(); ++j) {
      if (j == i) continue;
      if (p.DistanceTo(robots_[j].pose()) < r + robots_[j].options().radius_m) {
        with = "robot " + std::to_string(j);
      }
    }
    if (!with.empty()) {
      collisions_.push_back(Collision{static_cast<int>(i), t_ns_, p, with});
      stopped_[i] = true;
      robots_[i].Reset(p);
    }
  }
}

std::vector<Surface> Simulation::OtherRobots(int robot) const {
  std::vector<Surface> out;
  for (std::size_t j = 0; j < robots_.size(); ++j) {
    if (static_cast<int>(j) == robot) continue;
    WorldObject body;
    body.kind = ObjectKind::kCylinder;
    body.center = Eigen::Vector2d(robots_[j].pose().x_m, robots_[j].pose().y_m);
    body.radius_m = robots_[j].options().radius_m;
    body.height_m = options_.robot_body_height_m;
    AppendObjectSurfaces(body, body_textures_[j], &out, LightDirection(world_));
  }
  return out;
}

cv::Mat Simulation::RenderClean(int robot) const {
  const auto& r = robots_.at(static_cast<std::size_t>(robot));
  return renderer().Render(camera_.model, WorldFromCamera(r.pose(), camera_.mount),
                           OtherRobots(robot));
}

cv::Mat Simulation::Render(int robot) {
  cv::Mat image = RenderClean(robot);
  const auto i = static_cast<std::size_t>(robot);
  const std::uint64_t frame = frames_[i]++;
  if (!camera_.effects.Any()) return image;
  Rng rng = Rng::Derive(seed_, (frame << 8) + i + 1);
  return ApplyEffects(image, camera_.effects, &rng);
}

static DriveOptions ParseDriveOptionsUnchecked(const std::string& yaml_text,
                                               const std::string& name) {
  DriveOptions options;
  const io::YamlMap root = io::YamlMap::LoadString(yaml_text, name);
  root.CheckKnownKeys({"render", "simulation", "drive"});
  if (root.Has("render")) {
    const io::YamlMap r = root.GetMap("render");
    r.CheckKnownKeys({"edge_supersample", "near_m", "far_m", "anisotropy"});
    auto& o = options.sim.render;
    o.edge_supersample = r.GetInt("edge_supersample", o.edge_supersample);
    o.near_m = r.GetDouble("near_m", o.near_m);
    o.far_m = r.GetDouble("far_m", o.far_m);
    o.anisotropy = r.GetDouble("anisotropy", o.anisotropy);
    try {
      o.Validate();
    } catch (const InputError& e) {
      r.Fail("", e.what());
    }
  }
  if (root.Has("simulation")) {
    const io::YamlMap s = root.GetMap("simulation");
    s.CheckKnownKeys({"physics_dt_s", "robot_body_height_m"});
    options.sim.physics_dt_s = s.GetDouble("physics_dt_s", options.sim.physics_dt_s);
    options.sim.robot_body_height_m =
        s.GetDouble("robot_body_height_m", options.sim.robot_body_height_m);
  }
  if (root.Has("drive")) {
    const io::YamlMap d = root.GetMap("drive");
    d.CheckKnownKeys({"timeout_factor", "stop_on_collision"});
    options.timeout_factor = d.GetDouble("timeout_factor", options.timeout_factor);
    options.stop_on_collision = d.GetBool("stop_on_collision", options.stop_on_collision);
  }
  try {
    options.Validate();
  } catch (const InputError& e) {
    throw InputError(name + ": " + e.what());
  }
  return options;
}

DriveOptions ParseDriveOptions(const std::string& yaml_text, const std::string& name) {
  return io::WithYamlErrors(name, [&] { return ParseDriveOptionsUnchecked(yaml_text, name); });
}

std::vector<Pose2> PosesAlongTaughtPath(const Scenario& scenario, int count) {
  std::vector<Pose2> poses;
  Simulation s(scenario.world, scenario.camera, {}, 1);
  s.AddRobot(scenario.teach_start, scenario.robot);
  ScriptedDriver driver(scenario.teach_start, scenario.teach_path, scenario.teach_speed_mps);
  while (!driver.done() && poses.size() < 5000) {
    poses.push_back(s.robot(0).pose());
    s.SetCommand(0, driver.Update(s.robot(0).pose()));
    s.Advance(0.1);
  }
  std::vector<Pose2> picked;
  for (int i = 0; i < count && !poses.empty(); ++i) {
    picked.push_back(
        poses[static_cast<std::size_t>(i) * poses.size() / static_cast<std::size_t>(count)]);
  }
  return picked;
}

DriveSummary DriveTaughtPath(const Scenario& scenario, const DriveOptions& options,
                             const std::function<void(const DriveFrame&)>& on_frame) {
  options.Validate();
  scenario.Validate();
  Simulation sim(scenario.world, scenario.camera, options.sim, options.seed);
  const int robot = sim.AddRobot(scenario.teach_start, scenario.robot);
  ScriptedDriver driver(scenario.teach_start, scenario.teach_path, scenario.teach_speed_mps);
  const double period = 1.0 / scenario.camera.rate_hz;
  double rotation = 0.0;
  for (const PathStep& s : scenario.teach_path) {
    if (s.kind == PathStep::Kind::kRotate) rotation += std::abs(s.rotate_rad);
  }
  const double nominal = scenario.PathLength() / scenario.teach_speed_mps + rotation / 0.5 + 5.0;
  const double timeout = options.timeout_factor * nominal;
  DriveSummary summary;
  Pose2 last = scenario.teach_start;
  while (true) {
    DriveFrame frame;
    frame.index = summary.frames;
    frame.t_ns = sim.now_ns();
    frame.truth = sim.robot(robot).pose();
    frame.odometry = sim.robot(robot).odometry();
    if (options.render_frames && !(options.skip_render && options.skip_render(frame)))
      frame.image = sim.Render(robot);
    if (on_frame) on_frame(frame);
    ++summary.frames;
    summary.distance_m += frame.truth.DistanceTo(last);
    last = frame.truth;
    if (driver.done()) {
      summary.completed = true;
      summary.status = "completed";
      break;
    }
    if (sim.collided(robot) && options.stop_on_collision) {
      const Collision& c = sim.collisions().front();
      summary.collided = true;
      char buf[128];
      std::snprintf(buf, sizeof(buf), "collision with %s at (%.2f, %.2f) after %.1f s",
                    c.with.c_str(), c.pose.x_m, c.pose.y_m, ToSeconds(c.t_ns));
      summary.status = buf;
      break;
    }
    if (ToSeconds(sim.now_ns()) > timeout) {
      char buf[96];
      std::snprintf(buf, sizeof(buf), "timeout after %.1f s (3x the nominal duration)",
                    ToSeconds(sim.now_ns()));
      summary.status = buf;
      break;
    }
    sim.SetCommand(robot, driver.Update(sim.robot(robot).pose()));
    sim.Advance(period);
  }
  summary.collided = summary.collided || sim.collided(robot);
  summary.duration_s = ToSeconds(sim.now_ns());
  return summary;
}

}  // namespace mapless::sim
