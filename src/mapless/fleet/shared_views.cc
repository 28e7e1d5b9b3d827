// Learned views in the route log (issue 45; route_log.h): a follower offers a view its repeat
// learned (ShareViewRecord), the leader takes it into its route (RouteCopy::TakeView) as a record
// after the end of the route, and every follower applies that record to its copy
// (RouteCopy::Apply), so followers learn from each other's repeats.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <utility>

#include "mapless/core/check.h"
#include "mapless/fleet/route_log.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"
#include "mapless/route/route_store.h"

namespace mapless::fleet {

namespace {

namespace fs = std::filesystem;

std::string ViewJson(int keyframe, double offset_px, int learned_at, int last_used) {
  nlohmann::json j;
  j["keyframe"] = keyframe;
  j["offset_px"] = offset_px;
  if (learned_at > 0) {
    j["learned_at"] = learned_at;
    j["last_used"] = last_used;
  }
  return j.dump();
}

int JsonInt(const nlohmann::json& j, const char* key, long long lo, long long hi,
            const std::string& what) {
  if (!j.contains(key) || !j[key].is_number_integer())
    throw InputError(what + ": " + key + ": missing or not a whole number");
  const long long v = j[key].get<long long>();
  if (v < lo || v > hi)
    throw InputError(what + ": " + key + " = " + std::to_string(v) + " (must be in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "])");
  return static_cast<int>(v);
}

// A view record's part 0: keyframe and offset (and, in the log, the visits), checked against a
// route of `keyframes` keyframes `width` pixels wide.
struct ViewFields {
  int keyframe = 0;
  double offset_px = 0.0;
  int learned_at = 0;
  int last_used = 0;
};
ViewFields ParseViewFields(const Record& record, std::size_t keyframes, int width, bool in_log,
                           const std::string& what) {
  MAPLESS_CHECK(record.type == RecordType::kView && record.parts.size() == 2,
                what << ": not a view record");
  MAPLESS_CHECK(record.parts[1].size() <= io::kMaxKeyframeFileBytes,
                what << ": a view file of " << record.parts[1].size() << " bytes (at most "
                     << io::kMaxKeyframeFileBytes << ")");
  const nlohmann::json j = nlohmann::json::parse(record.parts[0], nullptr, false);
  MAPLESS_CHECK(!j.is_discarded() && j.is_object(), what << ": not a JSON object");
  ViewFields f;
  f.keyframe = JsonInt(j, "keyframe", 0, static_cast<long long>(keyframes) - 1, what);
  MAPLESS_CHECK(j.contains("offset_px") && j["offset_px"].is_number(),
                what << ": offset_px: missing or not a number");
  f.offset_px = j["offset_px"].get<double>();
  MAPLESS_CHECK(std::isfinite(f.offset_px) && std::abs(f.offset_px) <= width,
                what << ": offset_px = " << f.offset_px << " (the route's images are " << width
                     << " pixels wide)");
  if (in_log) {
    f.learned_at = JsonInt(j, "learned_at", 1, 1 << 30, what);
    f.last_used = JsonInt(j, "last_used", f.learned_at, 1 << 30, what);
  }
  return f;
}

bool SameView(const route::KeyframeView& a, const route::KeyframeView& b) {
  if (a.offset_px != b.offset_px || a.keypoints.size() != b.keypoints.size() ||
      a.descriptors.size() != b.descriptors.size() || a.descriptors.type() != b.descriptors.type())
    return false;
  return a.descriptors.empty() || cv::norm(a.descriptors, b.descriptors, cv::NORM_INF) == 0.0;
}

}  // namespace

Record ShareViewRecord(const route::Keyframe& keyframe, const route::KeyframeView& view) {
  route::Keyframe file;
  file.index = keyframe.index;
  file.t_ns = keyframe.t_ns;
  file.keypoints = view.keypoints;
  file.descriptors = view.descriptors;
  Record r;
  r.type = RecordType::kView;
  r.parts = {ViewJson(keyframe.index, view.offset_px, 0, 0), route::SerializeKeyframe(file)};
  return r;
}

Record StoredViewRecord(const route::Keyframe& keyframe, const route::KeyframeView& view,
                        std::string file_bytes) {
  Record r;
  r.type = RecordType::kView;
  r.parts = {ViewJson(keyframe.index, view.offset_px, view.learned_at, view.last_used),
             std::move(file_bytes)};
  return r;
}

std::string RouteCopy::TakeView(const Record& offered, int max_views) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string what = "a follower's view";
  MAPLESS_CHECK(header_ && header_->kind == RouteKind::kFunnel,
                what << ": this leader's route is not a funnel route");
  MAPLESS_CHECK(complete_, what << ": the route is not complete yet");
  const ViewFields f =
      ParseViewFields(offered, keyframes_.size(), header_->image_width, false, what);
  route::Keyframe& kf = keyframes_[static_cast<std::size_t>(f.keyframe)];
  route::KeyframeView view = route::DecodeView(offered.parts[1], kf, FunnelManifest(*header_),
                                               what + " of keyframe " + std::to_string(f.keyframe));
  view.offset_px = f.offset_px;
  MAPLESS_CHECK(static_cast<int>(kf.views.size()) + 1 < max_views,
                what << ": keyframe " << f.keyframe << " has its " << max_views
                     << " views already (lead --take-views)");
  for (const route::KeyframeView& v : kf.views)
    MAPLESS_CHECK(!SameView(v, view), what << ": keyframe " << f.keyframe << " has it already");
  Record r;
  r.type = RecordType::kView;
  r.sequence = log_.size();
  r.parts = {ViewJson(f.keyframe, f.offset_px, visits_ + 1, visits_ + 1), offered.parts[1]};
  ApplyOne(r, nullptr);
  log_.back().written_ns = WallClockNs();
  return "took a view of keyframe " + std::to_string(f.keyframe) + " from a follower (visit " +
         std::to_string(visits_) + ", record " + std::to_string(r.sequence) + "; " +
         std::to_string(kf.views.size() + 1) + " views there)";
}

void RouteCopy::ApplyView(const Record& record, const std::string& what) {
  MAPLESS_CHECK(header_->kind == RouteKind::kFunnel, what << ": in an eigenspace route");
  MAPLESS_CHECK(complete_, what << ": before the end of the route");
  const ViewFields f = ParseViewFields(record, keyframes_.size(), header_->image_width, true, what);
  MAPLESS_CHECK(f.learned_at >= last_view_visit_, what << ": learned_at " << f.learned_at
                                                       << " before the previous view's ("
                                                       << last_view_visit_ << ")");
  route::Keyframe& kf = keyframes_[static_cast<std::size_t>(f.keyframe)];
  MAPLESS_CHECK(
      kf.views.size() < static_cast<std::size_t>(route::kMaxViewsPerKeyframe),
      what << ": keyframe " << f.keyframe << " has " << kf.views.size() << " views (the limit)");
  route::KeyframeView view =
      route::DecodeView(record.parts[1], kf, FunnelManifest(*header_), what + " view");
  view.offset_px = f.offset_px;
  view.learned_at = f.learned_at;
  view.last_used = f.last_used;
  view.file = route::ViewFileName(f.keyframe, f.learned_at);
  for (const route::KeyframeView& v : kf.views)
    MAPLESS_CHECK(v.file != view.file,
                  what << ": keyframe " << f.keyframe << " has a view of visit " << f.learned_at);
  // The view's file as the record carries it (byte for byte the leader's), then the manifest.
  io::WriteFileAtomic((fs::path(dir_) / view.file).string(), record.parts[1]);
  kf.views.push_back(std::move(view));
  const int visits_before = visits_;
  const int last_before = last_view_visit_;
  last_view_visit_ = f.learned_at;
  route::Route r;
  r.detector = header_->detector;
  r.image_width = header_->image_width;
  r.image_height = header_->image_height;
  r.complete = true;
  r.visits = visits_ = std::max(visits_, f.learned_at);
  r.keyframes = std::move(keyframes_);
  try {
    route::SaveViews(dir_, &r);
  } catch (...) {
    keyframes_ = std::move(r.keyframes);
    keyframes_[static_cast<std::size_t>(f.keyframe)].views.pop_back();
    visits_ = visits_before;
    last_view_visit_ = last_before;
    throw;
  }
  keyframes_ = std::move(r.keyframes);
  funnel_cache_.reset();
}

std::vector<Record> RouteCopy::LoadViewRecords(const route::Manifest& m) {
  struct Stored {
    int learned_at;
    int keyframe;
    Record record;
  };
  std::vector<Stored> stored;
  for (std::size_t i = 0; i < m.keyframes.size() && i < keyframes_.size(); ++i) {
    route::Keyframe& kf = keyframes_[i];
    for (const route::ManifestView& v : m.keyframes[i].views) {
      const std::string path = (fs::path(dir_) / v.data).string();
      std::string bytes = io::ReadFile(path, io::kMaxKeyframeFileBytes);
      route::KeyframeView view = route::DecodeView(bytes, kf, FunnelManifest(*header_), path);
      view.offset_px = v.offset_px;
      view.learned_at = v.learned_at;
      view.last_used = v.last_used;
      view.file = v.data;
      stored.push_back({v.learned_at, kf.index, StoredViewRecord(kf, view, std::move(bytes))});
      kf.views.push_back(std::move(view));
    }
  }
  // In the order they were learned (a keyframe learns one view a visit).
  std::stable_sort(stored.begin(), stored.end(), [](const Stored& a, const Stored& b) {
    return a.learned_at != b.learned_at ? a.learned_at < b.learned_at : a.keyframe < b.keyframe;
  });
  visits_ = m.visits;
  last_view_visit_ = stored.empty() ? 0 : stored.back().learned_at;
  std::vector<Record> records;
  for (Stored& s : stored) records.push_back(std::move(s.record));
  return records;
}

}  // namespace mapless::fleet
