// Markov localization over the route index (Section 4 of Payá et al., Eq. 5-6): a belief over the
// route images, predicted by convolving it with a Gaussian motion model centred on the advance the
// odometry (or the commanded speed) reports, and corrected by an observation model that is a sum
// of Gaussian kernels on the k route images most similar to the current one, each weighted by a
// confidence from its similarity. The position is the maximum of the belief; its probability (the
// belief mass within ±probability_window images of it) says how sure the robot is, and a
// probability that stays low means the robot is lost.
//
// Defaults follow the paper where it gives them (k = 5); the widths are in route images.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "mapless/localization/nearest.h"

namespace mapless::localization {

struct MarkovOptions {
  int kernels = 5;                     // k, route images in the observation model (Eq. 6)
  double kernel_sigma_images = 1.5;    // σ of each kernel (Eq. 6), route images
  double motion_sigma_images = 0.3;    // motion model standard deviation per update ...
  double motion_sigma_fraction = 0.3;  // ... plus this fraction of the predicted advance
  // p(z|x) never falls below this, so that a wrong belief can recover from good observations.
  double observation_floor = 0.02;
  // Each prediction mixes this much of a uniform belief in (the robot may be anywhere: without it
  // the belief far from its peak underflows to zero and a wrong peak can never be left).
  double uniform_mixing = 0.0;
  int probability_window = 1;  // probability = belief mass within ± this many images
  // Lost: for lost_after_updates in a row, either the probability is below lost_probability or
  // the observation disagrees with the prediction (the predicted belief puts less than
  // min_agreement of the best possible weight on the places the image looks like). The second
  // catches a confident belief that the images contradict, which the posterior alone hides.
  double lost_probability = 0.15;
  double min_agreement = 0.1;
  int lost_after_updates = 10;
  void Validate() const;
};

enum class LocalizationStatus { kUninitialized, kTracking, kLost };
const char* LocalizationStatusName(LocalizationStatus status);

struct Localization {
  LocalizationStatus status = LocalizationStatus::kUninitialized;
  int index = -1;            // route image at the maximum of the belief
  double probability = 0.0;  // belief mass around it
  double agreement = 0.0;    // Σ prior(x) p(z|x) / max p(z|x): does the image fit the prediction
  std::vector<Neighbour> neighbours;  // the k most similar route images (observation)
};

class MarkovLocalizer {
 public:
  explicit MarkovLocalizer(MarkovOptions options = {});

  // Belief uniform over `route_images` (nothing known).
  void ResetUniform(int route_images);
  // Belief a Gaussian around `index` (after initial localization).
  void ResetAt(int route_images, double index, double sigma_images);

  // One predict + update: `advance_images` is the motion since the last update in route images
  // (odometry distance / image spacing). `projections` (K x N) may have grown since the last call
  // (a leader still teaching): new images get the belief's floor.
  Localization Update(const Eigen::MatrixXf& projections, const Eigen::VectorXf& query,
                      double advance_images);
  // The same over the places of a route whose places have several images (learned views,
  // issue 45): the belief is over `places`, and the observation's k kernels sit on the k places
  // whose nearest column is nearest the query (NearestPlaces; column_place[c] is column c's).
  Localization Update(const Eigen::MatrixXf& projections, const std::vector<int>& column_place,
                      int places, const Eigen::VectorXf& query, double advance_images);

  // Prediction alone (dead reckoning, not in the paper): the belief moves with the odometry and the
  // index limits, with no observation (the images are known not to fit, e.g. where something the
  // route images showed is gone). The status stays kTracking and the lost count is not advanced.
  Localization Predict(int route_images, double advance_images);

  const Eigen::VectorXd& belief() const { return belief_; }
  // Changes MarkovOptions::uniform_mixing from the next prediction on.
  void set_uniform_mixing(double mixing);
  // From the next update on, the belief before route image `min_index` and beyond `max_index` is
  // set to zero after each prediction (the robot cannot be there, e.g. further along than it has
  // driven). A negative value removes that limit; a limit that would leave no belief is ignored.
  void set_index_limits(int min_index, int max_index) {
    min_index_ = min_index;
    max_index_ = max_index;
  }
  const MarkovOptions& options() const { return options_; }

 private:
  void Grow(int route_images);
  void PredictFor(int route_images, double advance_images);  // grow, predict, limits
  Localization Correct(int route_images, std::vector<Neighbour> neighbours);  // Eq. 5-6
  void Predict(double advance_images);
  void ApplyIndexLimits();
  Localization Peak() const;  // index and probability at the belief's maximum

  MarkovOptions options_;
  Eigen::VectorXd belief_;
  Eigen::VectorXd scratch_;
  int low_updates_ = 0;
  int min_index_ = -1;
  int max_index_ = -1;
};

}  // namespace mapless::localization
