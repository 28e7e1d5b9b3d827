// What a report shows of one run frame by frame: commands over time, the funnel-lane slopes, the
// localization and its belief, the dominant plane, and pictures of chosen frames. Each trace hands
// out an observer for the method's run (eval's observers: called once per frame) and then adds
// its plots and pictures to the run's report section. Used by `mapless demo` for its three runs and
// by `mapless eval SUITE --report` for the first run of each entry.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/run/report.h"

namespace mapless::run {

class RunTrace {
 public:
  virtual ~RunTrace() = default;
  // Adds the plots and pictures after what the section has (its error along the path).
  virtual void AddTo(RunSection* section) const = 0;
};

// Teach & repeat: commands, slopes (Kassir et al., Eq. 6-7), and at 20%, 50% and 80% of
// `expected_frames` the current image next to its destination keyframe with the matches.
class RepeatTrace : public RunTrace {
 public:
  RepeatTrace(const eval::TaughtRoute& taught, double dt_s)
      : taught_(&taught), dt_s_(dt_s), expected_frames_(taught.path.size()) {}
  void Step(const cv::Mat& image, const navigation::RepeatStep& s);
  eval::RepeatObserver Observer() {
    return [this](const Pose2&, const cv::Mat& image, const navigation::RepeatStep& s) {
      Step(image, s);
    };
  }
  void AddTo(RunSection* section) const override;

 private:
  void AddPictures(RunSection* section) const;

  const eval::TaughtRoute* taught_;
  double dt_s_;
  std::size_t expected_frames_;
  int frame_ = 0;
  std::vector<double> t_, v_, omega_, slope_x_, slope_y_;
  std::vector<std::pair<cv::Mat, std::string>> pictures_;
};

// The eigenspace follower: commands, the localized route image and its probability, and the
// Markov belief over time as a picture.
class EigenspaceTrace : public RunTrace {
 public:
  explicit EigenspaceTrace(double dt_s) : dt_s_(dt_s) {}
  void Step(const navigation::FollowerStep& step);
  eval::EigenspaceObserver Observer() {
    return [this](const navigation::FollowerStep& step, const Pose2&) { Step(step); };
  }
  void AddTo(RunSection* section) const override;

 private:
  double dt_s_;
  int frame_ = 0;
  std::vector<double> t_, v_, omega_, index_, probability_;
  std::vector<std::vector<float>> beliefs_;
};

// The visual potential: commands, the dominant plane's fraction, and at frames 15, 60 and 120 the
// plane over the image with the force's direction.
class PotentialTrace : public RunTrace {
 public:
  explicit PotentialTrace(double dt_s) : dt_s_(dt_s) {}
  void Step(const cv::Mat& image, const navigation::PotentialStep& step);
  eval::PotentialObserver Observer() {
    return [this](const Pose2&, const cv::Mat& image, const navigation::PotentialStep& step) {
      Step(image, step);
    };
  }
  void AddTo(RunSection* section) const override;

 private:
  double dt_s_;
  int frame_ = 0;
  std::vector<double> t_, v_, omega_, plane_;
  std::vector<std::pair<cv::Mat, std::string>> pictures_;
};

}  // namespace mapless::run
