// Dominant-plane (ground) detection from optical flow (Ohnishi & Imiya, Sections 3.3-3.6).
//
// The planar flow of the ground between two frames is fitted by RANSAC, with the paper's affine
// model x' = Ax + b (Eq. 3-4) or a homography (which the affine model approximates, Eq. 2). A pixel
// belongs to the dominant plane when its flow is within epsilon of the planar flow (Eq. 5). The
// plane is reported only when it covers more than half of the region of interest; otherwise the
// result says "no plane" (a result, not an error).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mapless::ground {

enum class PlaneModel { kAffine, kHomography };
PlaneModel ParsePlaneModel(const std::string& name);  // "affine" or "homography"
const char* PlaneModelName(PlaneModel model);

struct DominantPlaneOptions {
  PlaneModel model = PlaneModel::kHomography;
  double epsilon_px = 1.0;  // tolerance |u - u_hat| of Eq. 5, pixels
  // Not in the paper: a tolerance that also grows with the planar flow, epsilon_px +
  // epsilon_relative * |u_hat|. Flow errors grow with the flow (large near the bottom of the image,
  // near zero at the horizon), so a fixed epsilon is too strict below and too loose above
  // (distant buildings, whose flow is as small as the ground's there). 0: the paper's Eq. 5.
  double epsilon_relative = 0.0;
  // Not in the paper: the tolerance in the direction of the planar flow, as a fraction of the
  // tolerance (1: a circle, the paper's). Something standing on the ground is nearer than the
  // ground behind it, so it moves more than the planar flow, along it: 0.5 cuts the feet of walls,
  // cars and people out of the plane where their flow is still within the tolerance (`mapless
  // ground`: 0.5; CamVid IoU 0.803 -> 0.820).
  double nearer_fraction = 1.0;
  int sample_step_px = 4;  // RANSAC draws from flow vectors on this grid
  // RANSAC: adaptive iteration count from the inlier ratio (confidence), capped at the paper's
  // fixed count width * height / 2.
  double confidence = 0.999;
  // Cap on the RANSAC iterations; 0: the paper's width * height / 2. A frame whose flow fits no
  // plane well (a wall, a garbage pair) runs to the cap, so a controller wants a small one: it
  // only needs to know whether more than half the view is one plane (inlier ratio 0.4 needs 270
  // iterations at 0.999).
  int max_iterations = 0;
  // Region of interest: the rows below this fraction of the image height (0: the whole image, as
  // in the paper; 0.5: the bottom half, for a forward-looking car camera).
  double roi_top_fraction = 0.0;
  // Not in the paper: RANSAC draws only from the bottom `fit_bottom_fraction` of the ROI (1: the
  // whole ROI, the paper). A robot stands on the ground, so the rows just ahead of it are ground
  // unless it is already touching something; fitting there keeps a large, close obstacle (whose
  // own flow is planar too) from winning the consensus. Inliers are still taken everywhere.
  double fit_bottom_fraction = 1.0;
  double min_plane_fraction = 0.5;  // the plane must cover more than this of the ROI
  // Property 1 of the paper: the ground touches the bottom of the image. Keep only the plane
  // regions connected to the bottom row (after a small morphological opening).
  bool bottom_connected = true;
  int open_px = 1;  // radius of the opening that cuts thin bridges (0: none)
  void Validate() const;
};

struct DominantPlane {
  bool found = false;  // false: no plane covers enough of the ROI (e.g. a wall fills the view)
  cv::Mat mask;        // d(x, y, t): CV_8UC1, 255 on the dominant plane, 0 elsewhere
  cv::Mat model;       // 3x3 (CV_64F): x' = model * x (affine: last row 0 0 1)
  double roi_fraction = 0.0;  // fraction of the ROI on the plane
  int iterations = 0;         // RANSAC iterations used
};

// Dominant plane of the flow field `flow` (CV_32FC2, from frame t to t+1).
DominantPlane DetectDominantPlane(const cv::Mat& flow, const DominantPlaneOptions& options);

// The planar flow field u_hat(x) = model(x) - x (CV_32FC2) of a fitted model, at `size`.
cv::Mat PlanarFlow(const cv::Mat& model, cv::Size size);

// Hierarchical detection (Algorithm 3): the dominant plane of each pyramid layer's flow, finest
// first, and the inclusion measures P(D_l ⊂ D_{l+1}) = |D_l ∩ D_{l+1}| / |D_{l+1}| (Eq. 22-26),
// computed at layer l's resolution.
struct HierarchicalPlanes {
  std::vector<DominantPlane> layers;  // layers[0] is full resolution
  std::vector<double> inclusion;      // inclusion[l] = P(D_l ⊂ D_{l+1})
};
HierarchicalPlanes DetectHierarchicalPlanes(const std::vector<cv::Mat>& layer_flows,
                                            const DominantPlaneOptions& options);

// P(A ⊂ B) = |A ∩ B| / |B| for masks (B resized to A's size by nearest neighbour); 1 when B is
// empty.
double InclusionMeasure(const cv::Mat& a, const cv::Mat& b);

// Intersection over union of two 0/255 masks inside `roi` (the whole image when empty).
double MaskIoU(const cv::Mat& a, const cv::Mat& b, const cv::Rect& roi = {});

}  // namespace mapless::ground
