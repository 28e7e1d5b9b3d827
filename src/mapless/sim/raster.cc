// The renderer's surfaces prepared for one camera (raster.h).
#include "mapless/sim/raster.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace mapless::sim::raster {
namespace {

// Clips a polygon (camera frame) to z >= near and returns its projected bounds, or false.
bool ScreenBounds(const std::vector<Eigen::Vector3d>& poly, const CameraModel& cam, double near_m,
                  int* x0, int* x1, int* y0, int* y1) {
  std::vector<Eigen::Vector3d> clipped;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = poly[i];
    const Eigen::Vector3d& b = poly[(i + 1) % n];
    const bool ina = a.z() >= near_m;
    const bool inb = b.z() >= near_m;
    if (ina) clipped.push_back(a);
    if (ina != inb) {
      const double t = (near_m - a.z()) / (b.z() - a.z());
      clipped.push_back(a + t * (b - a));
    }
  }
  if (clipped.empty()) return false;
  double minx = 1e30, maxx = -1e30, miny = 1e30, maxy = -1e30;
  for (const auto& p : clipped) {
    const double u = cam.fx * p.x() / p.z() + cam.cx;
    const double v = cam.fy * p.y() / p.z() + cam.cy;
    minx = std::min(minx, u);
    maxx = std::max(maxx, u);
    miny = std::min(miny, v);
    maxy = std::max(maxy, v);
  }
  const double lim = 1e6;
  *x0 = std::max(0, static_cast<int>(std::floor(std::max(minx, -lim))) - 1);
  *x1 = std::min(cam.width - 1, static_cast<int>(std::ceil(std::min(maxx, lim))) + 1);
  *y0 = std::max(0, static_cast<int>(std::floor(std::max(miny, -lim))) - 1);
  *y1 = std::min(cam.height - 1, static_cast<int>(std::ceil(std::min(maxy, lim))) + 1);
  return *x0 <= *x1 && *y0 <= *y1;
}

bool Prepare(const Surface& s, const CameraModel& cam, const Rigid3& camera_from_world,
             const RenderOptions& options, Prepared* out) {
  const Eigen::Matrix3d r = camera_from_world.linear();
  const Eigen::Vector3d o = camera_from_world * s.origin;
  const Eigen::Vector3d e1 = r * s.e1;
  const Eigen::Vector3d e2 = r * s.e2;
  Eigen::Vector3d n = e1.cross(e2);
  const double n_norm = n.norm();
  if (n_norm < 1e-12) return false;
  n /= n_norm;
  double k = n.dot(o);
  // One-sided surfaces face along e1 x e2: the camera (origin) must be on that side.
  if (s.one_sided && k >= 0.0) return false;
  if (std::abs(k) < 1e-9) return false;  // camera in the plane: edge-on

  Prepared p{};
  p.shape = s.shape;
  switch (s.shape) {
    case Surface::Shape::kParallelogram: {
      const std::vector<Eigen::Vector3d> poly = {o, o + e1, o + e1 + e2, o + e2};
      if (!ScreenBounds(poly, cam, options.near_m, &p.x0, &p.x1, &p.y0, &p.y1)) return false;
      break;
    }
    case Surface::Shape::kDisk: {
      const std::vector<Eigen::Vector3d> poly = {o - e1 - e2, o + e1 - e2, o + e1 + e2,
                                                 o - e1 + e2};
      if (!ScreenBounds(poly, cam, options.near_m, &p.x0, &p.x1, &p.y0, &p.y1)) return false;
      break;
    }
    case Surface::Shape::kPlane:
      p.x0 = 0;
      p.x1 = cam.width - 1;
      p.y0 = 0;
      p.y1 = cam.height - 1;
      break;
  }
  // Directions d = (xd, yd, 1) with xd = (x - cx) / fx: fold the intrinsics into the coefficients
  // so that the inner loop works on pixel-independent (xd, yd).
  const Eigen::Vector3d a1 = e1 / e1.squaredNorm();
  const Eigen::Vector3d a2 = e2 / e2.squaredNorm();
  p.nx = static_cast<float>(n.x());
  p.ny = static_cast<float>(n.y());
  p.nz = static_cast<float>(n.z());
  p.k = static_cast<float>(k);
  p.a1x = static_cast<float>(a1.x());
  p.a1y = static_cast<float>(a1.y());
  p.a1z = static_cast<float>(a1.z());
  p.c1 = static_cast<float>(a1.dot(o));
  p.a2x = static_cast<float>(a2.x());
  p.a2y = static_cast<float>(a2.y());
  p.a2z = static_cast<float>(a2.z());
  p.c2 = static_cast<float>(a2.dot(o));
  const Texture& tex = *s.texture;
  const double size = tex.levels[0].cols;
  double texel_m = tex.texel_m;
  if (tex.fit) {
    p.s_scale = static_cast<float>(size);
    p.t_scale = static_cast<float>(size);
    texel_m = std::sqrt(e1.norm() * e2.norm()) / size;
  } else {
    p.s_scale = static_cast<float>(e1.norm() / texel_m);
    p.t_scale = static_cast<float>(e2.norm() / texel_m);
  }
  p.lod_base = static_cast<float>(0.5 * std::log2(k * k / (cam.fx * cam.fy * texel_m * texel_m)));
  p.shade = s.shade;
  p.levels = tex.views.data();
  p.max_level = static_cast<int>(tex.views.size()) - 1;
  *out = p;
  return true;
}

}  // namespace

// The surfaces of the world and the extra ones, prepared for this camera pose (those behind the
// camera or outside the view are left out); a surface's group ties the faces of one object.
std::vector<Prepared> PrepareSurfaces(const std::vector<Surface>& own,
                                      const std::vector<Surface>& extra, const CameraModel& cam,
                                      const Rigid3& camera_from_world,
                                      const RenderOptions& options) {
  std::vector<Prepared> prepared;
  prepared.reserve(own.size() + extra.size());
  int list_offset = 0;
  const int group_base = 1 << 20;  // grouped surfaces: group_base + list offset + edge_group
  for (const auto* list : {&own, &extra}) {
    for (std::size_t k = 0; k < list->size(); ++k) {
      const Surface& s = (*list)[k];
      Prepared p;
      if (!Prepare(s, cam, camera_from_world, options, &p)) continue;
      p.group = s.edge_group >= 0 ? group_base + list_offset + s.edge_group
                                  : static_cast<int>(prepared.size());
      prepared.push_back(p);
    }
    list_offset += static_cast<int>(list->size());
  }

  return prepared;
}

}  // namespace mapless::sim::raster
