// Renders the grayscale image a pinhole camera sees in a World.
//
// Every surface is planar: parallelograms (walls, box faces, cylinder facets, posters), disks
// (cylinder tops) and infinite planes (ground, ceiling). The renderer casts one ray per pixel
// against the surfaces whose screen bounding box covers it (a z-buffered ray caster), samples each
// texture from its mip pyramid with trilinear filtering (no texture aliasing at any distance), and
// then supersamples the pixels on silhouettes (where the visible surface changes between
// neighbours): an S x S grid of sub-rays measures how much of the pixel each surface covers, and
// each covering surface is shaded once at the centroid of its sub-rays (multisample
// anti-aliasing). Edges thus move smoothly under sub-pixel motion and optical flow is meaningful.
// Deterministic: the same world, camera and pose give identical bytes.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "mapless/sim/camera.h"
#include "mapless/sim/world.h"

namespace mapless::sim {

struct RenderOptions {
  int edge_supersample = 4;  // S: S x S coverage rays per silhouette pixel (1: no anti-aliasing)
  double near_m = 0.02;      // nearest visible distance along the optical axis, metres
  double far_m = 150.0;      // farthest visible distance, metres
  double anisotropy = 0.5;   // mip choice: 0 = geometric mean of the footprint (sharper),
                             // 1 = its long side (no aliasing at grazing angles, blurrier)
  void Validate() const;
};

// One planar surface, in world coordinates.
struct Surface {
  enum class Shape { kParallelogram, kDisk, kPlane };
  Shape shape = Shape::kParallelogram;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner (parallelogram), centre (disk)
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();     // first edge / radius vector / plane axis
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitY();     // second edge / radius vector / plane axis
  bool one_sided = false;                            // visible only from the side of e1 x e2
  float shade = 1.0f;                                // brightness factor (fixed light)
  // Surfaces with the same non-negative group form one smooth object (a cylinder's facets): the
  // boundaries between them are not silhouettes and are not supersampled.
  int edge_group = -1;
  std::shared_ptr<const Texture> texture;
};

// The direction towards the light of a world (World::light_azimuth_deg), unit length.
Eigen::Vector3d LightDirection(const World& world);

// Appends the surfaces of one object (its texture must be generated already), shaded by a light
// in `light` (unit; LightDirection).
void AppendObjectSurfaces(const WorldObject& object, std::shared_ptr<const Texture> texture,
                          std::vector<Surface>* out, const Eigen::Vector3d& light);

// The renderer's per-pixel passes run as AVX2 code where the CPU has it and as baseline code
// otherwise (SSE2 on x86-64; the target's own elsewhere): the same bytes either way, only the time
// differs. RenderKernels() names the one in use, "avx2" or "baseline";
// UseBaselineRenderKernels(true) makes every later render use the baseline (benches, tests).
const char* RenderKernels();
void UseBaselineRenderKernels(bool baseline);

class Renderer {
 public:
  // Generates every texture of the world (shared between objects with the same spec).
  Renderer(const World& world, RenderOptions options);

  // Renders the view of a camera at world_from_camera. `extra` surfaces (other robots) are drawn
  // too. Returns a CV_8UC1 image of camera.width x camera.height.
  cv::Mat Render(const CameraModel& camera, const Rigid3& world_from_camera,
                 const std::vector<Surface>& extra = {}) const;

  const std::vector<Surface>& surfaces() const { return surfaces_; }

 private:
  RenderOptions options_;
  std::vector<Surface> surfaces_;
  double sky_top_ = 200.0;
  double sky_horizon_ = 170.0;
};

}  // namespace mapless::sim
