// On-disk route store: a directory, versioned, written incrementally and crash-safe.
//
//   ROUTE/manifest.json          {"format": "mapless-route", "version": 1, "detector": "orb",
//                                 "image_width": 320, "image_height": 240, "complete": true,
//                                 "keyframes": [{"index": 0, "t_s": 0.0,
//                                                "data": "keyframes/000000.yml",
//                                                "thumbnail": "keyframes/000000.png"}, ...]}
//   ROUTE/keyframes/NNNNNN.yml   OpenCV FileStorage YAML: keypoints, descriptors, segment tracks
//   ROUTE/keyframes/NNNNNN.png   the downscaled keyframe image
//
// Every file is written atomically (temporary file, fsync, rename), the keyframe's files before the
// manifest that lists it. A teach killed at any moment therefore leaves a route that loads, with
// every keyframe completed before the kill; `complete` is false until the teach finished.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/route/route.h"

namespace mapless::route {

inline constexpr int kRouteFormatVersion = 1;
// A route with learned views (issue 45) is written as version 2: its keyframe entries list their
// views, ROUTE/keyframes/NNNNNN-visit-VVVV.yml each (a keyframe file: the view's features, the
// keyframe's index and time), with the offset and the visits that learned and last used it. A
// mapless that reads version 1 only refuses it, saying which version it reads. A route without
// views stays version 1.
inline constexpr int kRouteViewsFormatVersion = 2;
inline constexpr int kMaxViewsPerKeyframe = 64;
// A view file mapless wrote into a route: "NNNNNN-visit-VVVV.EXT" (keyframes/*.yml, views/*.png).
// Only such files are ever removed from a route (a user's "my-visit-notes.txt" is not).
bool IsViewFileName(const std::string& name, const std::string& extension);

struct Manifest;

class RouteWriter {
 public:
  // Creates DIR (and DIR/keyframes) and writes an empty manifest. Throws InputError when DIR
  // already holds a route: replacing a route is io::OutputDirectory's business (the old one stays
  // whole until the new one is done).
  RouteWriter(std::string dir, std::string detector, int image_width, int image_height);
  // Goes on writing a route an interrupted teach (or a follower's copy) left in DIR; throws
  // InputError naming the manifest when it cannot be read or the route has learned views.
  static std::unique_ptr<RouteWriter> Reopen(const std::string& dir);
  // Writes one keyframe, then the manifest that lists it.
  void Append(const Keyframe& keyframe);
  // The same from the bytes of its two files (SerializeKeyframe, PNG), e.g. a leader's record.
  // Nothing lists them until Flush(), which flushes them to disk and then writes the manifest:
  // many keyframes, one manifest (a follower catching up).
  void AppendEncoded(int index, Timestamp t_ns, std::string_view yml, std::string_view png);
  void Flush();
  // Marks the route complete (and flushes).
  void Finish();
  int keyframes() const { return static_cast<int>(entries_.size()); }
  bool complete() const { return complete_; }

 private:
  RouteWriter(std::string dir, const Manifest& manifest);
  void WriteManifest() const;
  struct Entry {
    int index;
    double t_s;
    mutable std::string text;  // its part of the manifest, written once (WriteManifest)
  };
  std::string dir_;
  std::string detector_;
  int width_;
  int height_;
  bool complete_ = false;
  std::vector<Entry> entries_;
  std::vector<std::string> pending_;  // written, not yet flushed
};

// A keyframe's data file, as the route store writes it (deterministic), and where a keyframe's
// files live in the route directory ("keyframes/NNNNNN", without extension).
std::string SerializeKeyframe(const Keyframe& keyframe);
std::string KeyframeFileStem(int index);

// Loads a route; throws InputError naming the file and what is wrong (missing, truncated,
// corrupt, wrong version, over a limit of io/limits.h, or inconsistent: an unknown detector,
// descriptors another detector wrote, fewer than 2 keyframes, time going backwards, keypoints
// outside the image). Whatever a repeat relies on is checked here, so `mapless route info`
// catches it.
Route LoadRoute(const std::string& dir);

// Writes the views of `route` (loaded from `dir`) that are not stored yet, then the manifest that
// lists every view the route now has (version 2, with route->visits), atomically; view files no
// longer listed (pruned) are removed after. The caller holds the directory's lock
// (io::DirectoryLock) for the whole run that learned them.
void SaveViews(const std::string& dir, Route* route);

// Where a keyframe's view learned at visit `learned_at` is stored
// ("keyframes/NNNNNN-visit-VVVV.yml").
std::string ViewFileName(int keyframe, int learned_at);
// A learned view of `keyframe` from its file's bytes (a fleet record), checked as LoadRoute checks
// a stored view against the route's `header` (detector, image size) and the keyframe (index,
// time). Errors name `name`. The view's offset and visits are the caller's.
KeyframeView DecodeView(const std::string& yml, const Keyframe& keyframe, const Manifest& header,
                        const std::string& name);

// The parsers behind LoadRoute, on bytes already read (`name` stands for the file in errors).
// Fuzzed by fuzz/fuzz_route_manifest.cc and fuzz/fuzz_route_keyframe.cc.
struct ManifestView {
  std::string data;  // relative to the route directory, like the keyframe's
  double offset_px = 0.0;
  int learned_at = 0;
  int last_used = 0;
};
struct ManifestEntry {
  int index = 0;
  double t_s = 0.0;       // the keyframe's time, as its file says
  std::string data;       // relative to the route directory; never absolute, never ".."
  std::string thumbnail;  // likewise
  std::vector<ManifestView> views;
};
struct Manifest {
  int version = kRouteFormatVersion;
  int visits = 0;
  std::string detector;
  int image_width = 0;
  int image_height = 0;
  bool complete = false;
  std::vector<ManifestEntry> keyframes;
};
Manifest ParseManifest(const std::string& text, const std::string& name);
// A keyframe's data file (everything but its image).
Keyframe ParseKeyframe(const std::string& text, const std::string& name);
// A keyframe from the bytes of its two files (a leader's record), checked as LoadRoute checks a
// stored one against the route's `header` (detector, image size; its keyframe list is not used):
// its index must be `index` and, unless it is the first, its time after `after_t_ns`. Errors name
// `name` (".yml" / ".png" appended).
Keyframe DecodeKeyframe(const std::string& yml, const std::string& png, const Manifest& header,
                        int index, Timestamp after_t_ns, const std::string& name);

}  // namespace mapless::route
