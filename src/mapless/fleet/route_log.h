// The route as a log of records (record.h), on both sides of the network.
//
// RouteCopy keeps a route directory in step with a log: a leader applies each record it makes to
// its own route directory before it serves it, and a follower applies the records it receives to
// its copy, with the same code, so the two directories are equal byte for byte. Records are
// checked before anything is written (a bad record changes nothing), written with the route
// store's crash safety (files flushed before the manifest that lists them), and a copy left by a
// killed process is reopened where it stopped: its next sequence number follows from the files.
//
// A funnel route's places may hold views that repeats learned (issue 45, navigation/experiences.h):
// they follow the end record, one view record each, in the order of the visits that learned them
// (shared_views.cc). A follower offers the leader a view it learned (ShareViewRecord); a leader
// that takes views (TakeView) appends it to its log as the next record, and every follower applies
// it to its copy. The log stays append-only: a place full of views takes no more (no pruning of
// a served route).
//
// For the eigenspace route the records carry the route images, not the model: the incremental PCA
// is deterministic given the same images in the same order, so RouteCopy rebuilds exactly the
// leader's eigenspace (navigation::AppearanceLeader::AddStored), one image per record.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "mapless/fleet/record.h"
#include "mapless/navigation/appearance.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route.h"
#include "mapless/route/route_store.h"

namespace mapless::io {
class DirectoryLock;
}

namespace mapless::fleet {

enum class RouteKind { kFunnel, kEigenspace };
const char* RouteKindName(RouteKind kind);  // "funnel", "eigenspace"
RouteKind ParseRouteKind(const std::string& name);

// What the header record says.
struct RouteHeader {
  RouteKind kind = RouteKind::kFunnel;
  int image_width = 0;  // the camera's frames
  int image_height = 0;
  std::string detector = "orb";  // funnel
  int low_width = 0;             // eigenspace
  int low_height = 0;
};
Record HeaderRecord(const RouteHeader& header);
RouteHeader ParseHeader(const Record& record);  // throws InputError
// The route store's header of a funnel route (detector, image size), what its records are checked
// against (route::DecodeKeyframe, route::DecodeView).
route::Manifest FunnelManifest(const RouteHeader& header);

// The records of a leader's teach (sequence numbers are set by RouteCopy::Apply's caller).
Record KeyframeRecord(const route::Keyframe& keyframe);
Record ImageRecord(const route::StoredAppearanceImage& image);  // image.low: 8-bit
Record EndRecord();
// A view a follower's repeat learned of `keyframe`, as it offers it to the leader (sequence 0;
// part 0 keyframe and offset, part 1 the view's keyframe file).
Record ShareViewRecord(const route::Keyframe& keyframe, const route::KeyframeView& view);
// A stored view as a log record (its visits with it; `file_bytes`: its file as stored).
Record StoredViewRecord(const route::Keyframe& keyframe, const route::KeyframeView& view,
                        std::string file_bytes);

class RouteCopy {
 public:
  // Opens DIR: the copy a previous run left there (resumed after its last whole record), or a new
  // one when DIR is empty or missing (created). Throws InputError when DIR holds something else,
  // or when another process writes it (a teach, a leader, a follower: DIR is locked while the
  // RouteCopy lives).
  explicit RouteCopy(std::string dir);
  ~RouteCopy();

  // The next sequence number this copy needs (0: nothing yet).
  std::uint64_t next_sequence() const;
  bool complete() const;
  std::optional<RouteHeader> header() const;
  // Records held, for serving: record `sequence` as the leader encodes it (written_ns from when it
  // was applied, or loaded from disk).
  std::vector<Record> RecordsFrom(std::uint64_t from, std::size_t max) const;

  // Applies records in order, starting at next_sequence(): each is checked, written, and the
  // manifest that lists them is written once at the end (flushed). A record whose sequence is not
  // the next one throws InputError before anything of it is written.
  void Apply(const std::vector<Record>& records);
  // A leader's own record, with what it was encoded from (a keyframe record's keyframe, an image
  // record's 8-bit route image): as Apply({record}), without decoding what was just encoded.
  void ApplyOwn(const Record& record, std::optional<route::Keyframe> keyframe,
                const cv::Mat& image_low = {});
  // A leader's: takes a view a follower offers (ShareViewRecord) into a complete funnel route as
  // the next record, learned at the route's next visit. Throws InputError (one line: why) when the
  // route is not a complete funnel route, the record is malformed or does not fit the route, the
  // keyframe has max_views views (the taught one included) or this view already. Returns a line
  // for the log.
  std::string TakeView(const Record& offered, int max_views);
  // Record `sequence` as it goes on the wire (EncodeRecord): encoded once, when first asked, and
  // shared by every follower it is sent to; null when there is no such record yet.
  std::shared_ptr<const std::string> Encoded(std::uint64_t sequence) const;

  // The route as the methods see it (built when asked and cached until the next record): null
  // until there are at least 2 keyframes / 1 route image. The eigenspace is built here, from the
  // route images applied since the last call (a follower catching up stores the records first
  // and builds the model once, when its method asks).
  std::shared_ptr<const route::Route> FunnelRoute() const;
  std::shared_ptr<const route::AppearanceRoute> AppearanceRoute() const;
  // The funnel route read in pieces (a follower's method, on its own thread): appends to `route`
  // the keyframes it lacks and the views its keyframes lack, sets its header fields and
  // completeness, and says whether anything changed. Its work is the new keyframes', whatever the
  // route's length (FunnelRoute() copies the whole route each time it changed).
  bool UpdateFunnel(route::Route* route) const;

  const std::string& dir() const { return dir_; }

 private:
  // `decoded`: the keyframe of a keyframe record, when it was decoded ahead (or empty).
  // `low`: the image record's image, when it is known (empty: decoded from the record).
  void ApplyOne(const Record& record, std::optional<route::Keyframe>* decoded,
                const cv::Mat& low = {});
  void ApplyView(const Record& record, const std::string& what);  // shared_views.cc
  // The views of a loaded route's keyframes (keyframes_), in keyframes_ and as their records in
  // the order they were learned (shared_views.cc).
  std::vector<Record> LoadViewRecords(const route::Manifest& manifest);
  void Load();

  std::string dir_;
  std::unique_ptr<io::DirectoryLock> lock_;
  mutable std::mutex mutex_;
  std::optional<RouteHeader> header_;
  bool complete_ = false;
  std::vector<Record> log_;  // every record held, in order (sequence = index)
  mutable std::vector<std::shared_ptr<const std::string>> encoded_;  // log_'s, as first sent
  std::unique_ptr<route::RouteWriter> keyframe_writer_;
  std::unique_ptr<route::AppearanceRouteWriter> image_writer_;
  std::vector<route::Keyframe> keyframes_;
  mutable std::vector<route::StoredAppearanceImage> model_pending_;  // applied, not in the model
  std::size_t images_ = 0;
  double last_distance_m_ = 0.0;
  int visits_ = 0;           // the route's visits (views learned at 1..visits_)
  int last_view_visit_ = 0;  // the last view record's learned_at (they come in order)
  mutable std::shared_ptr<const route::Route> funnel_cache_;
  // The eigenspace, under its own lock (building it does not hold up Apply).
  mutable std::mutex model_mutex_;
  mutable std::unique_ptr<navigation::AppearanceLeader> model_;
  mutable bool model_finished_ = false;
  mutable std::shared_ptr<const route::AppearanceRoute> appearance_cache_;
};

}  // namespace mapless::fleet
