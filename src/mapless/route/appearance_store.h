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

struct StoredAppearanceImage {
  cv::Mat low;              // CV_8UC1, low_width x low_height
  double distance_m = 0.0;  // odometry distance from the route start
  Pose2 odometry;           // the leader's odometry when it was taken
};

struct StoredAppearanceRoute {
  int image_width = 0;  // the camera's frames
  int image_height = 0;
  int low_width = 0;
  int low_height = 0;
  bool complete = false;
  std::vector<StoredAppearanceImage> images;
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

// Loads a stored appearance route; throws InputError naming the file and what is wrong.
StoredAppearanceRoute LoadAppearanceRoute(const std::string& dir);
// The manifest alone, from bytes (`name` for errors): fuzzed like the keyframe manifest.
StoredAppearanceRoute ParseAppearanceManifest(const std::string& text, const std::string& name,
                                              std::vector<std::string>* files);

}  // namespace mapless::route
