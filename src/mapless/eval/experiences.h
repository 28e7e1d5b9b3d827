// `mapless eval experiences` (issue 45): experiences on real multi-session images. A dataset in the
// layout of the GRIEF Stromovka sessions: DIR/SSPP.png, the view of place PP at session SS (two
// digits each; sessions in time order), and DIR/offsets.txt, lines "place session dx_px": the
// horizontal offset of that session's view relative to the place's first session (ground truth).
//
// Each place is taught from its first session; every later session, in order, is a visit: the
// shift against the taught view alone (the single view), and against the place's views as they
// stand (navigation/experiences.h), chained to the taught view by the offsets the route measured
// when it learned them (never the ground truth). A visit the rules say to learn becomes a view.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mapless/features/shift.h"
#include "mapless/navigation/experiences.h"

namespace mapless::eval {

struct SessionsDataset {
  std::string dir;
  // place -> its sessions in time order, each with its image file and ground-truth offset (px)
  struct Visit {
    int session = 0;
    std::string image;
    double offset_px = 0.0;
  };
  std::map<int, std::vector<Visit>> places;
};

// Reads DIR/offsets.txt and checks that every line names an image that exists; throws InputError
// naming the file and line when not (and when a place has fewer than two sessions).
SessionsDataset LoadSessionsDataset(const std::string& dir);

struct PlaceFigures {
  int place = 0;
  int visits = 0;         // sessions after the first
  int single_within = 0;  // visits whose single-view shift is within the tolerance
  int experiences_within = 0;
  int learned = 0;         // views learned
  int learned_within = 0;  // ... whose stored offset is within the tolerance of the truth
  int views = 1;           // views the place has at the end
  double single_fraction() const;
  double experiences_fraction() const;
};

struct ExperiencesFigures {
  std::vector<PlaceFigures> places;
  double tolerance_px = 17.5;
  double single_fraction = 0.0;  // over every visit of every place
  double experiences_fraction = 0.0;
  int learned = 0;
  int learned_within = 0;
};

struct ExperiencesEvalOptions {
  navigation::ExperienceOptions experiences;
  features::ShiftOptions shift;
  double tolerance_px = 17.5;
};

ExperiencesFigures EvalExperiences(const SessionsDataset& data,
                                   const ExperiencesEvalOptions& options);

}  // namespace mapless::eval
