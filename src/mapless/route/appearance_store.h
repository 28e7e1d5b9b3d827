// On-disk appearance route (Payá et al.): what a leader taught, stored so that a follower in
// another process, or later, rebuilds exactly the leader's model. The incremental PCA is
// deterministic given the same images in the same order, so the store keeps the route images
// (each low-resolution image, 8-bit, before normalisation), not the eigenspace.
//
//   ROUTE/appearance.json       {"format": "mapless-appearance-route", "version": 1,
//                                "image_width": 320, "image_height": 240,
//                                "low_width": 64, "low_height": 64, "complete": true,
//                                "images": [{"index": 0, "distance_m": 0.0, "x_m": 0, "y_m": 0,
//                                            "theta_rad": 0, "file": "images/000000.png"}, ...]}
//   ROUTE/images/NNNNNN.png     the low-resolution route image (lossless)
//
// A route with learned views (issue 45; `follow --learn`, navigation/appearance_experiences.h)
// is version 2: the head has "visits" (the follows that learned into it) and an image entry may
// list "views": [{"file": "views/NNNNNN-visit-VVVV.png", "offset_px", "learned_at",
// "last_used"}], each a low-resolution view of the same place learned on a later visit. A mapless
// that reads version 1 only refuses it, saying which version it reads; a route without views
// stays version 1. SaveAppearanceViews writes the view files first, then the manifest.
//
// Crash-safe like the keyframe store: each image file is written atomically before the manifest
// that lists it, so a teach killed at any moment leaves a route that loads with every whole image.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::route {

inline constexpr int kAppearanceRouteFormatVersion = 1;
inline constexpr int kAppearanceRouteViewsFormatVersion = 2;
inline constexpr int kMaxAppearanceViewsPerImage = 64;

// A view of a route image's place learned on a later visit (version 2).
struct StoredAppearanceView {
  cv::Mat low;           // CV_8UC1, as the route image (empty until loaded or after writing)
  double offset_px = 0;  // its sub-window shift against the route image (chained; see .h above)
  int learned_at = 1;    // the visit that learned it (1 ..visits)
  int last_used = 1;     // the last visit that steered or localized by it
  std::string file;      // "views/NNNNNN-visit-VVVV.png"; empty until written
};

struct StoredAppearanceImage {
  cv::Mat low;                              // CV_8UC1, low_width x low_height
  double distance_m = 0.0;                  // odometry distance from the route start
  Pose2 odometry;                           // the leader's odometry when it was taken
  std::vector<StoredAppearanceView> views;  // learned views of this place (version 2)
};

struct StoredAppearanceRoute {
  int image_width = 0;  // the camera's frames
  int image_height = 0;
  int low_width = 0;
  int low_height = 0;
  bool complete = false;
  int visits = 0;  // follows that learned into the route (version 2)
  std::vector<StoredAppearanceImage> images;
  int views() const;  // learned views over all images
};

class AppearanceRouteWriter {
 public:
  // Creates DIR and DIR/images and writes an empty manifest; throws InputError when DIR already
  // holds a route.
  AppearanceRouteWriter(std::string dir, int image_width, int image_height, int low_width,
                        int low_height);
  // Goes on writing a route an interrupted teach (or a follower's copy) left in DIR.
  static std::unique_ptr<AppearanceRouteWriter> Reopen(const std::string& dir);
  void Append(const StoredAppearanceImage& image);
  // The same from the image's PNG bytes (a leader's record): nothing lists it until Flush(), which
  // flushes the new files to disk and then writes the manifest.
  void AppendEncoded(const StoredAppearanceImage& entry, std::string_view png);
  void Flush();
  void Finish();  // marks the route complete (and flushes)
  int images() const { return static_cast<int>(entries_.size()); }
  bool complete() const { return header_.complete; }
  const StoredAppearanceRoute& header() const { return header_; }  // without images

 private:
  AppearanceRouteWriter() = default;
  void WriteManifest() const;
  std::string dir_;
  StoredAppearanceRoute header_;
  std::vector<StoredAppearanceImage> entries_;   // low images dropped after writing
  mutable std::vector<std::string> entry_text_;  // their parts of the manifest, made once
  std::vector<std::string> pending_;             // written, not yet flushed
};

// A route image's manifest entry without its file (distance and odometry), as a JSON object, and
// back (checked like the manifest; errors name `name`).
std::string AppearanceEntryJson(const StoredAppearanceImage& image);
StoredAppearanceImage ParseAppearanceEntry(const std::string& text, const std::string& name);
// Where route image `index` lives in the route directory ("images/NNNNNN.png").
std::string AppearanceImageFile(int index);

// Writes the learned views of `route` (loaded from `dir`, images and views as
// LoadAppearanceRoute gives them, views changed since): the new view files first (each
// atomically, then flushed), then the manifest (version 2, atomically), then the files of views
// no longer listed are removed. A kill at any moment leaves the route as it was or as it is
// after. Fills in the new views' `file`. The caller holds the directory's lock.
void SaveAppearanceViews(const std::string& dir, StoredAppearanceRoute* route);
// "views/NNNNNN-visit-VVVV.png": the file of a view of route image `index` learned at `visit`.
std::string AppearanceViewFile(int index, int visit);

// Loads a stored appearance route; throws InputError naming the file and what is wrong.
StoredAppearanceRoute LoadAppearanceRoute(const std::string& dir);
// The manifest alone, from bytes (`name` for errors): fuzzed like the keyframe manifest.
StoredAppearanceRoute ParseAppearanceManifest(const std::string& text, const std::string& name,
                                              std::vector<std::string>* files);

}  // namespace mapless::route
