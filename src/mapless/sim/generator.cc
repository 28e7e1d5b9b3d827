#include "mapless/sim/generator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/core/pose.h"
#include "mapless/core/rng.h"
#include "mapless/sim/generator_layout.h"

namespace mapless::sim {

namespace gen {

namespace {

constexpr double kDenseStepM = 0.1;

Eigen::Vector2d Heading(double th) { return {std::cos(th), std::sin(th)}; }

}  // namespace

std::string Num(double v, int precision) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(precision);
  out << (std::abs(v) < 0.5 * std::pow(10.0, -precision) ? 0.0 : v);
  return out.str();
}

double Distance(const Footprint& f, const Eigen::Vector2d& p) {
  switch (f.kind) {
    case Footprint::kSegment: {
      const Eigen::Vector2d ab = f.b - f.a;
      const double len2 = ab.squaredNorm();
      const double t = len2 > 0.0 ? std::clamp((p - f.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      return (f.a + t * ab - p).norm();
    }
    case Footprint::kBox: {
      const Eigen::Vector2d d = p - f.center;
      const double c = std::cos(f.yaw_rad), s = std::sin(f.yaw_rad);
      const double lx = std::abs(c * d.x() + s * d.y()) - f.half.x();
      const double ly = std::abs(-s * d.x() + c * d.y()) - f.half.y();
      const double outside = std::hypot(std::max(lx, 0.0), std::max(ly, 0.0));
      return outside > 0.0 ? outside : std::max(lx, ly);
    }
    case Footprint::kCircle:
      return (p - f.center).norm() - f.radius_m;
  }
  return 0.0;
}

double Layout::ClearanceToPath(const Footprint& f) const {
  double best = 1e9;
  for (const PathPoint& q : dense) best = std::min(best, Distance(f, q.p));
  return best;
}

double Layout::ClearanceToSolids(const Eigen::Vector2d& p) const {
  double best = 1e9;
  for (const Footprint& f : solids) best = std::min(best, Distance(f, p));
  return best;
}

bool Layout::Fits(const Footprint& f, double path_clearance_m, double object_gap_m) const {
  if (ClearanceToPath(f) < path_clearance_m) return false;
  const Eigen::Vector2d c = f.kind == Footprint::kSegment ? 0.5 * (f.a + f.b) : f.center;
  const double r = f.kind == Footprint::kBox ? f.half.norm() : f.radius_m;
  for (const Footprint& o : solids) {
    if (Distance(o, c) < r + object_gap_m) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// The taught path.

namespace {

struct Piece {
  std::vector<Eigen::Vector2d> points;  // waypoints (empty for a turn in place)
  double rotate_rad = 0.0;
  double end_theta = 0.0;
  std::string feature;
};

Piece Straight(const Eigen::Vector2d& p, double th, double length_m) {
  Piece piece;
  const int n = std::max(1, static_cast<int>(std::ceil(length_m / 0.5)));
  for (int i = 1; i <= n; ++i) piece.points.push_back(p + Heading(th) * (length_m * i / n));
  piece.end_theta = th;
  piece.feature = "straight";
  return piece;
}

// An arc of radius r turning by `angle` (positive: left), waypoints every 0.25 m or so.
void AppendArc(Piece* piece, Eigen::Vector2d p, double th, double r, double angle) {
  const double side = angle > 0.0 ? 1.0 : -1.0;
  const Eigen::Vector2d centre = p + side * r * Heading(th + kPi / 2);
  const int n = std::max(2, static_cast<int>(std::ceil(std::abs(angle) * r / 0.25)));
  for (int i = 1; i <= n; ++i) {
    const double a = th + angle * i / n;
    piece->points.push_back(centre - side * r * Heading(a + kPi / 2));
  }
  piece->end_theta = th + angle;
}

Piece DrawPiece(Rng& rng, const std::string& kind, const Eigen::Vector2d& p, double th) {
  // Weights of straight, S-curve, turn, hairpin, turn in place; radii by kind (a corridor's walls
  // follow the path: no hairpins, no turns in place, wide radii).
  struct Mix {
    double straight, s_curve, turn, hairpin, in_place, r_min, r_max;
  };
  const Mix mix = kind == "corridor"   ? Mix{0.4, 0.35, 0.25, 0.0, 0.0, 1.6, 3.0}
                  : kind == "outdoor"  ? Mix{0.3, 0.3, 0.2, 0.12, 0.08, 1.0, 3.0}
                  : kind == "car_park" ? Mix{0.35, 0.2, 0.3, 0.08, 0.07, 1.2, 2.5}
                                       : Mix{0.25, 0.3, 0.2, 0.13, 0.12, 0.7, 1.6};
  const double u = rng.Uniform();
  const double left = rng.Uniform() < 0.5 ? 1.0 : -1.0;
  const double r = rng.Uniform(mix.r_min, mix.r_max);
  Piece piece;
  if (u < mix.straight) return Straight(p, th, rng.Uniform(1.5, 3.5));
  if (u < mix.straight + mix.s_curve) {
    const double a = DegToRad(rng.Uniform(35.0, 75.0));
    AppendArc(&piece, p, th, r, left * a);
    AppendArc(&piece, piece.points.back(), piece.end_theta, r, -left * a);
    piece.feature = "s_curve";
  } else if (u < mix.straight + mix.s_curve + mix.turn) {
    AppendArc(&piece, p, th, r, left * DegToRad(rng.Uniform(50.0, 110.0)));
    piece.feature = "turn";
  } else if (u < mix.straight + mix.s_curve + mix.turn + mix.hairpin) {
    AppendArc(&piece, p, th, std::max(0.7, 0.75 * r), left * kPi);
    piece.feature = "hairpin";
  } else {
    piece.rotate_rad = left * DegToRad(rng.Uniform(45.0, 100.0));
    piece.end_theta = th + piece.rotate_rad;
    piece.feature = "turn_in_place";
  }
  // Every curve ends on a short straight run, so that pieces do not run into each other.
  const Piece tail = Straight(piece.points.empty() ? p : piece.points.back(), piece.end_theta,
                              rng.Uniform(0.8, 1.6));
  piece.points.insert(piece.points.end(), tail.points.begin(), tail.points.end());
  return piece;
}

// The dense polyline of a piece from `from` (every kDenseStepM).
std::vector<Eigen::Vector2d> Densify(const Eigen::Vector2d& from,
                                     const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> out;
  Eigen::Vector2d a = from;
  for (const Eigen::Vector2d& b : points) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kDenseStepM)));
    for (int i = 1; i <= n; ++i) out.push_back(a + (b - a) * (static_cast<double>(i) / n));
    a = b;
  }
  return out;
}

}  // namespace

void Layout::DrawPath(double target_length_m, double separation_m) {
  Eigen::Vector2d p(0.0, 0.0);
  double th = 0.0;
  // Behind the start: a follower may start there, and nothing may stand on it.
  for (int i = 15; i >= 1; --i) dense.push_back({Eigen::Vector2d(-kDenseStepM * i, 0.0), -1.0});
  dense.push_back({p, 0.0});
  auto add = [&](const Piece& piece) {
    const std::vector<Eigen::Vector2d> d = Densify(p, piece.points);
    double s = dense.back().s_m;
    Eigen::Vector2d last = p;
    for (const Eigen::Vector2d& q : d) {
      s += (q - last).norm();
      last = q;
      dense.push_back({q, s});
    }
    if (piece.rotate_rad != 0.0) {
      PathItem turn;
      turn.rotate = true;
      turn.rotate_rad = piece.rotate_rad;
      steps.push_back(turn);
    }
    for (const Eigen::Vector2d& q : piece.points) {
      PathItem go;
      go.target = q;
      steps.push_back(go);
    }
    if (!piece.points.empty()) p = piece.points.back();
    th = piece.end_theta;
    if (std::find(features.begin(), features.end(), piece.feature) == features.end())
      features.push_back(piece.feature);
  };
  add(Straight(p, th, rng.Uniform(2.5, 3.5)));
  int tries = 0;
  while (length_m() < target_length_m && tries < 60) {
    ++tries;
    const Piece piece = DrawPiece(rng, kind, p, th);
    // The new piece keeps `separation_m` from the path driven before the last few metres.
    const std::vector<Eigen::Vector2d> d = Densify(p, piece.points);
    const double recent = length_m() - 4.0;
    bool clear = true;
    for (const Eigen::Vector2d& q : d) {
      for (const PathPoint& old : dense) {
        if (old.s_m < recent && (old.p - q).norm() < separation_m) {
          clear = false;
          break;
        }
      }
      if (!clear) break;
    }
    if (clear) add(piece);
  }
}

double Layout::length_m() const { return dense.empty() ? 0.0 : dense.back().s_m; }

Eigen::Vector2d Layout::PointAt(double s_m, Eigen::Vector2d* tangent) const {
  for (std::size_t i = 1; i < dense.size(); ++i) {
    if (dense[i].s_m >= s_m || i + 1 == dense.size()) {
      const Eigen::Vector2d t = dense[i].p - dense[i - 1].p;
      if (tangent != nullptr)
        *tangent = t.norm() > 0.0 ? Eigen::Vector2d(t.normalized()) : Eigen::Vector2d(1.0, 0.0);
      return dense[i].p;
    }
  }
  if (tangent != nullptr) *tangent = Eigen::Vector2d(1.0, 0.0);
  return dense.empty() ? Eigen::Vector2d::Zero() : dense.back().p;
}

Eigen::Vector4d Layout::PathBounds() const {
  Eigen::Vector4d b(1e9, 1e9, -1e9, -1e9);
  for (const PathPoint& q : dense) {
    b[0] = std::min(b[0], q.p.x());
    b[1] = std::min(b[1], q.p.y());
    b[2] = std::max(b[2], q.p.x());
    b[3] = std::max(b[3], q.p.y());
  }
  return b;
}

}  // namespace gen

void GenerateOptions::Validate() const {
  const std::vector<std::string> kinds = GeneratorKinds();
  MAPLESS_CHECK(
      kind.empty() || std::find(kinds.begin(), kinds.end(), kind) != kinds.end(),
      "GenerateOptions.kind = '" << kind << "'; must be indoor, corridor, outdoor or car_park");
  MAPLESS_CHECK(obstacle_share >= 0.0 && obstacle_share <= 1.0,
                "GenerateOptions.obstacle_share = " << obstacle_share << "; must be in [0, 1]");
  MAPLESS_CHECK(
      textureless_share >= 0.0 && textureless_share <= 1.0,
      "GenerateOptions.textureless_share = " << textureless_share << "; must be in [0, 1]");
}

std::vector<std::string> GeneratorKinds() { return {"indoor", "corridor", "outdoor", "car_park"}; }

std::string GenerateScenarioYaml(const GenerateOptions& options) {
  options.Validate();
  gen::Layout layout(Rng::Derive(options.seed, 0x6e6e));
  const std::vector<std::string> kinds = GeneratorKinds();
  layout.kind = options.kind.empty() ? kinds[layout.rng.UniformInt(kinds.size())] : options.kind;
  layout.seed = options.seed;
  // The world's draws that do not depend on its layout come first, so that the share of worlds
  // with an obstacle or without texture is the same whatever the kind.
  layout.textureless = layout.rng.Uniform() < options.textureless_share;
  layout.with_obstacle = layout.rng.Uniform() < options.obstacle_share;
  gen::BuildWorld(&layout);
  return gen::WriteYaml(layout);
}

}  // namespace mapless::sim
