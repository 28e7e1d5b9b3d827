#include "mapless/fleet/route_log.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/features/features.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/output_dir.h"

namespace mapless::fleet {

namespace fs = std::filesystem;

namespace {

int HeaderInt(const nlohmann::json& j, const char* key, int lo, int hi) {
  if (!j.contains(key) || !j[key].is_number_integer())
    throw InputError(std::string("fleet header: ") + key + ": missing or not a whole number");
  const long long v = j[key].get<long long>();
  if (v < lo || v > hi)
    throw InputError(std::string("fleet header: ") + key + " = " + std::to_string(v) +
                     " (must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "])");
  return static_cast<int>(v);
}

// Catching up, a batch holds many keyframes, and parsing their files is most of what applying
// them costs: they are decoded on two threads first, each checked as it would be on its own (its
// index is its place in the batch; its time is checked against the previous keyframe's in order,
// by ApplyOne). A record whose decoding fails is left empty: ApplyOne decodes it again, in order,
// and refuses it with the same error as without this step.
std::vector<std::optional<route::Keyframe>> PreDecodeKeyframes(const std::vector<Record>& records,
                                                               std::optional<RouteHeader> header,
                                                               std::size_t keyframes) {
  std::vector<std::optional<route::Keyframe>> out(records.size());
  if (!records.empty() && records.front().type == RecordType::kHeader && !header) {
    try {
      header = ParseHeader(records.front());
    } catch (const InputError&) {
      return out;
    }
  }
  if (!header || header->kind != RouteKind::kFunnel) return out;
  std::vector<std::pair<std::size_t, int>> todo;  // (position in the batch, keyframe index)
  for (std::size_t i = 0; i < records.size(); ++i)
    if (records[i].type == RecordType::kKeyframe && records[i].parts.size() == 2)
      todo.emplace_back(i, static_cast<int>(keyframes + todo.size()));
  constexpr std::size_t kMinForThreads = 8;  // a live record or two is decoded where it is applied
  if (todo.size() < kMinForThreads) return out;
  const route::Manifest manifest = FunnelManifest(*header);
  const auto decode = [&](std::size_t first) {
    for (std::size_t k = first; k < todo.size(); k += 2) {
      const Record& r = records[todo[k].first];
      try {
        out[todo[k].first] = route::DecodeKeyframe(r.parts[0], r.parts[1], manifest, todo[k].second,
                                                   std::numeric_limits<Timestamp>::min(), "");
      } catch (const InputError&) {
        out[todo[k].first].reset();
      }
    }
  };
  std::thread other(decode, 1);
  decode(0);
  other.join();
  return out;
}

}  // namespace

route::Manifest FunnelManifest(const RouteHeader& h) {
  route::Manifest m;
  m.detector = h.detector;
  m.image_width = h.image_width;
  m.image_height = h.image_height;
  return m;
}

const char* RouteKindName(RouteKind kind) {
  return kind == RouteKind::kFunnel ? "funnel" : "eigenspace";
}

RouteKind ParseRouteKind(const std::string& name) {
  if (name == "funnel") return RouteKind::kFunnel;
  if (name == "eigenspace") return RouteKind::kEigenspace;
  throw InputError("route kind '" + name + "': must be funnel or eigenspace");
}

Record HeaderRecord(const RouteHeader& header) {
  nlohmann::json j;
  j["kind"] = RouteKindName(header.kind);
  j["image_width"] = header.image_width;
  j["image_height"] = header.image_height;
  if (header.kind == RouteKind::kFunnel) {
    j["detector"] = header.detector;
  } else {
    j["low_width"] = header.low_width;
    j["low_height"] = header.low_height;
  }
  Record r;
  r.type = RecordType::kHeader;
  r.parts = {j.dump()};
  return r;
}

RouteHeader ParseHeader(const Record& record) {
  MAPLESS_CHECK(record.type == RecordType::kHeader && record.parts.size() == 1,
                "fleet header: not a header record");
  const nlohmann::json j = nlohmann::json::parse(record.parts[0], nullptr, false);
  MAPLESS_CHECK(!j.is_discarded() && j.is_object(), "fleet header: not a JSON object");
  MAPLESS_CHECK(j.contains("kind") && j["kind"].is_string(), "fleet header: kind: missing");
  RouteHeader h;
  h.kind = ParseRouteKind(j["kind"].get<std::string>());
  h.image_width = HeaderInt(j, "image_width", io::kMinImageSide, io::kMaxImageSide);
  h.image_height = HeaderInt(j, "image_height", io::kMinImageSide, io::kMaxImageSide);
  if (h.kind == RouteKind::kFunnel) {
    MAPLESS_CHECK(j.contains("detector") && j["detector"].is_string(),
                  "fleet header: detector: missing");
    h.detector = j["detector"].get<std::string>();
    features::ParseDetectorType(h.detector);  // throws on an unknown one
  } else {
    h.low_width = HeaderInt(j, "low_width", 8, 1024);
    h.low_height = HeaderInt(j, "low_height", 8, 1024);
  }
  return h;
}

Record KeyframeRecord(const route::Keyframe& keyframe) {
  Record r;
  r.type = RecordType::kKeyframe;
  r.parts = {route::SerializeKeyframe(keyframe),
             io::EncodeImage(keyframe.thumbnail, ".png", "keyframe")};
  return r;
}

Record ImageRecord(const route::StoredAppearanceImage& image) {
  Record r;
  r.type = RecordType::kImage;
  r.parts = {route::AppearanceEntryJson(image), io::EncodeImage(image.low, ".png", "route image")};
  return r;
}

Record EndRecord() {
  Record r;
  r.type = RecordType::kEnd;
  return r;
}

RouteCopy::RouteCopy(std::string dir) : dir_(std::move(dir)) {
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw InputError(dir_ + ": is a file, not a directory; choose a directory for the route");
  fs::create_directories(dir_, ec);
  if (ec) throw InputError(dir_ + ": cannot create directory: " + ec.message());
  lock_ = std::make_unique<io::DirectoryLock>(dir_);
  Load();
}
RouteCopy::~RouteCopy() = default;

void RouteCopy::Load() {
  const bool funnel = fs::exists(fs::path(dir_) / "manifest.json");
  const bool eigen = fs::exists(fs::path(dir_) / "appearance.json");
  if (!funnel && !eigen) {
    if (fs::exists(dir_) && !fs::is_empty(dir_))
      throw InputError(dir_ +
                       ": holds something else than a route; choose a new or empty directory");
    return;
  }
  MAPLESS_CHECK(!(funnel && eigen),
                dir_ << ": holds two routes (manifest.json and appearance.json)");
  // Records are rebuilt from the files and applied to an in-memory state; the files stay as they
  // are (Reopen keeps writing after them).
  std::vector<Record> views;  // after the end record
  if (funnel) {
    const std::string path = (fs::path(dir_) / "manifest.json").string();
    const route::Manifest m = route::ParseManifest(io::ReadFile(path, io::kMaxManifestBytes), path);
    // A complete route takes no more keyframes (and one with views cannot be reopened for them).
    if (!m.complete) keyframe_writer_ = route::RouteWriter::Reopen(dir_);
    RouteHeader h;
    h.kind = RouteKind::kFunnel;
    h.image_width = m.image_width;
    h.image_height = m.image_height;
    h.detector = m.detector;
    header_ = h;
    log_.push_back(HeaderRecord(h));
    for (const route::ManifestEntry& e : m.keyframes) {
      Record r;
      r.type = RecordType::kKeyframe;
      r.parts = {io::ReadFile((fs::path(dir_) / e.data).string(), io::kMaxKeyframeFileBytes),
                 io::ReadFile((fs::path(dir_) / e.thumbnail).string(), io::kMaxImageFileBytes)};
      const Timestamp after = keyframes_.empty() ? 0 : keyframes_.back().t_ns;
      keyframes_.push_back(
          route::DecodeKeyframe(r.parts[0], r.parts[1], m, e.index, after,
                                (fs::path(dir_) / e.data).replace_extension().string()));
      log_.push_back(std::move(r));
    }
    complete_ = m.complete;
    views = LoadViewRecords(m);
  } else {
    image_writer_ = route::AppearanceRouteWriter::Reopen(dir_);
    const route::StoredAppearanceRoute& stored = image_writer_->header();
    RouteHeader h;
    h.kind = RouteKind::kEigenspace;
    h.image_width = stored.image_width;
    h.image_height = stored.image_height;
    h.low_width = stored.low_width;
    h.low_height = stored.low_height;
    header_ = h;
    log_.push_back(HeaderRecord(h));
    navigation::AppearanceLeaderOptions options;
    MAPLESS_CHECK(h.low_width == options.image.width && h.low_height == options.image.height,
                  dir_ << ": route images are " << h.low_width << "x" << h.low_height
                       << ", this mapless builds its model at " << options.image.width << "x"
                       << options.image.height);
    const route::StoredAppearanceRoute route = route::LoadAppearanceRoute(dir_);
    for (int i = 0; i < static_cast<int>(route.images.size()); ++i) {
      const route::StoredAppearanceImage& image = route.images[static_cast<std::size_t>(i)];
      Record r;
      r.type = RecordType::kImage;
      r.parts = {route::AppearanceEntryJson(image),
                 io::ReadFile((fs::path(dir_) / route::AppearanceImageFile(i)).string(),
                              io::kMaxImageFileBytes)};
      model_pending_.push_back(image);
      ++images_;
      last_distance_m_ = image.distance_m;
      log_.push_back(std::move(r));
    }
    complete_ = route.complete;
  }
  if (complete_) log_.push_back(EndRecord());
  for (Record& r : views) log_.push_back(std::move(r));
  const std::int64_t now = WallClockNs();
  for (std::size_t i = 0; i < log_.size(); ++i) {
    log_[i].sequence = i;
    log_[i].written_ns = now;
  }
}

std::uint64_t RouteCopy::next_sequence() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return log_.size();
}

bool RouteCopy::complete() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return complete_;
}

std::optional<RouteHeader> RouteCopy::header() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return header_;
}

std::vector<Record> RouteCopy::RecordsFrom(std::uint64_t from, std::size_t max) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Record> out;
  for (std::uint64_t s = from; s < log_.size() && out.size() < max; ++s) out.push_back(log_[s]);
  return out;
}

void RouteCopy::Apply(const std::vector<Record>& records) {
  std::lock_guard<std::mutex> lock(mutex_);
  // The records applied before a bad one are kept (and listed): the manifest is written either way.
  const auto flush = [&] {
    if (keyframe_writer_) keyframe_writer_->Flush();
    if (image_writer_) image_writer_->Flush();
  };
  const std::size_t first = log_.size();
  // A leader's own records are stamped once they are on disk (their latency counts from there).
  const auto stamp = [&] {
    const std::int64_t now = WallClockNs();
    for (std::size_t i = first; i < log_.size(); ++i)
      if (log_[i].written_ns == 0) log_[i].written_ns = now;
  };
  try {
    std::vector<std::optional<route::Keyframe>> decoded =
        PreDecodeKeyframes(records, header_, keyframes_.size());
    for (std::size_t i = 0; i < records.size(); ++i) ApplyOne(records[i], &decoded[i]);
  } catch (...) {
    flush();
    stamp();
    throw;
  }
  flush();
  stamp();
}

void RouteCopy::ApplyOwn(const Record& record, std::optional<route::Keyframe> keyframe,
                         const cv::Mat& image_low) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t first = log_.size();
  try {
    ApplyOne(record, &keyframe, image_low);
  } catch (...) {
    if (keyframe_writer_) keyframe_writer_->Flush();
    if (image_writer_) image_writer_->Flush();
    throw;
  }
  if (keyframe_writer_) keyframe_writer_->Flush();
  if (image_writer_) image_writer_->Flush();
  const std::int64_t now = WallClockNs();
  for (std::size_t i = first; i < log_.size(); ++i)
    if (log_[i].written_ns == 0) log_[i].written_ns = now;
}

std::shared_ptr<const std::string> RouteCopy::Encoded(std::uint64_t sequence) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (sequence >= log_.size()) return nullptr;
  if (encoded_.size() < log_.size()) encoded_.resize(log_.size());
  std::shared_ptr<const std::string>& e = encoded_[sequence];
  if (!e) e = std::make_shared<const std::string>(EncodeRecord(log_[sequence]));
  return e;
}

bool RouteCopy::UpdateFunnel(route::Route* route) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!header_ || header_->kind != RouteKind::kFunnel) return false;
  bool changed = false;
  if (route->keyframes.empty()) {
    route->detector = header_->detector;
    route->image_width = header_->image_width;
    route->image_height = header_->image_height;
  }
  for (std::size_t i = 0; i < route->keyframes.size() && i < keyframes_.size(); ++i) {
    if (route->keyframes[i].views.size() != keyframes_[i].views.size()) {  // views shared since
      route->keyframes[i].views = keyframes_[i].views;
      changed = true;
    }
  }
  for (std::size_t i = route->keyframes.size(); i < keyframes_.size(); ++i) {
    route->keyframes.push_back(keyframes_[i]);
    changed = true;
  }
  route->visits = visits_;
  if (route->complete != complete_) {
    route->complete = complete_;
    changed = true;
  }
  return changed;
}

void RouteCopy::ApplyOne(const Record& record, std::optional<route::Keyframe>* decoded,
                         const cv::Mat& low) {
  const std::string what =
      std::string(RecordTypeName(record.type)) + " record " + std::to_string(record.sequence);
  if (record.sequence != log_.size())
    throw InputError(what + ": expected sequence " + std::to_string(log_.size()));
  if (complete_ && record.type != RecordType::kView)
    throw InputError(what + ": after the end of the route");
  Record kept = record;
  if (record.type == RecordType::kHeader) {
    const RouteHeader h = ParseHeader(record);  // sequence 0 (checked by the decoder)
    fs::create_directories(dir_);
    if (h.kind == RouteKind::kFunnel) {
      keyframe_writer_ =
          std::make_unique<route::RouteWriter>(dir_, h.detector, h.image_width, h.image_height);
    } else {
      navigation::AppearanceLeaderOptions options;
      MAPLESS_CHECK(h.low_width == options.image.width && h.low_height == options.image.height,
                    what << ": route images are " << h.low_width << "x" << h.low_height
                         << ", this mapless builds its model at " << options.image.width << "x"
                         << options.image.height);
      image_writer_ = std::make_unique<route::AppearanceRouteWriter>(
          dir_, h.image_width, h.image_height, h.low_width, h.low_height);
    }
    header_ = h;
  } else if (!header_) {
    throw InputError(what + ": before the route header");
  } else if (record.type == RecordType::kKeyframe) {
    MAPLESS_CHECK(header_->kind == RouteKind::kFunnel, what << ": in an eigenspace route");
    const int index = static_cast<int>(keyframes_.size());
    MAPLESS_CHECK(index < io::kMaxKeyframes,
                  what << ": more than " << io::kMaxKeyframes << " keyframes");
    const Timestamp after_t_ns = keyframes_.empty() ? 0 : keyframes_.back().t_ns;
    const bool predecoded = decoded && *decoded && (*decoded)->index == index &&
                            (index == 0 || (*decoded)->t_ns > after_t_ns);
    route::Keyframe kf = predecoded ? std::move(**decoded)
                                    : route::DecodeKeyframe(record.parts[0], record.parts[1],
                                                            FunnelManifest(*header_), index,
                                                            after_t_ns, what + " keyframe");
    keyframe_writer_->AppendEncoded(index, kf.t_ns, record.parts[0], record.parts[1]);
    keyframes_.push_back(std::move(kf));
    funnel_cache_.reset();
  } else if (record.type == RecordType::kImage) {
    MAPLESS_CHECK(header_->kind == RouteKind::kEigenspace, what << ": in a funnel route");
    MAPLESS_CHECK(images_ < static_cast<std::size_t>(io::kMaxKeyframes),
                  what << ": more than " << io::kMaxKeyframes << " route images");
    route::StoredAppearanceImage image = route::ParseAppearanceEntry(record.parts[0], what);
    image.low = !low.empty()
                    ? low
                    : io::DecodeImage(record.parts[1], what + " image", cv::IMREAD_GRAYSCALE);
    MAPLESS_CHECK(image.low.cols == header_->low_width && image.low.rows == header_->low_height,
                  what << ": image is " << image.low.cols << "x" << image.low.rows
                       << ", the route's are " << header_->low_width << "x" << header_->low_height);
    MAPLESS_CHECK(images_ == 0 || image.distance_m >= last_distance_m_,
                  what << ": distance_m goes backwards");
    image_writer_->AppendEncoded(image, record.parts[1]);
    last_distance_m_ = image.distance_m;
    ++images_;
    model_pending_.push_back(std::move(image));
  } else if (record.type == RecordType::kEnd) {
    if (keyframe_writer_) {
      keyframe_writer_->Finish();
      keyframe_writer_.reset();  // done: the views that may follow write the manifest themselves
      funnel_cache_.reset();
    } else {
      image_writer_->Finish();
    }
    complete_ = true;
  } else if (record.type == RecordType::kView) {
    ApplyView(record, what);
  } else {
    throw InputError(what + ": not a route record");
  }
  log_.push_back(std::move(kept));
}

std::shared_ptr<const route::Route> RouteCopy::FunnelRoute() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!header_ || header_->kind != RouteKind::kFunnel || keyframes_.size() < 2) return nullptr;
  if (!funnel_cache_) {
    auto r = std::make_shared<route::Route>();
    r->detector = header_->detector;
    r->image_width = header_->image_width;
    r->image_height = header_->image_height;
    r->complete = complete_;
    r->visits = visits_;
    r->keyframes = keyframes_;
    funnel_cache_ = std::move(r);
  }
  return funnel_cache_;
}

std::shared_ptr<const route::AppearanceRoute> RouteCopy::AppearanceRoute() const {
  std::lock_guard<std::mutex> model_lock(model_mutex_);
  std::vector<route::StoredAppearanceImage> pending;
  bool complete = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!header_ || header_->kind != RouteKind::kEigenspace || images_ < 1) return nullptr;
    pending.swap(model_pending_);
    complete = complete_;
  }
  if (!model_) model_ = std::make_unique<navigation::AppearanceLeader>();
  for (const route::StoredAppearanceImage& image : pending)
    model_->AddStored(image.low, image.distance_m, image.odometry);
  const bool finish = complete && !model_finished_;
  if (finish) {
    model_->Finish();
    model_finished_ = true;
  }
  if (!appearance_cache_ || !pending.empty() || finish) appearance_cache_ = model_->Snapshot();
  return appearance_cache_;
}

}  // namespace mapless::fleet
