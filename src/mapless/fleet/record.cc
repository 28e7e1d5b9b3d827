#include "mapless/fleet/record.h"

#include <chrono>
#include <cstring>

#include "mapless/core/check.h"

namespace mapless::fleet {

namespace {

constexpr char kRecordMagic[4] = {'M', 'L', 'F', 'R'};
constexpr char kControlMagic[4] = {'M', 'L', 'F', 'C'};
constexpr std::size_t kSubscribeBytes = 4 + 1 + 1 + 2 + 8;
constexpr std::uint8_t kSubscribeType = 1;

template <typename T>
void Put(std::string* out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    out->push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xff));
}

// Reads little-endian numbers from untrusted bytes; every read is bounds-checked.
class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  T Get(const char* what) {
    Need(sizeof(T), what);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[pos_ + i])) << (8 * i);
    pos_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::string_view Take(std::size_t n, const char* what) {
    Need(n, what);
    const std::string_view s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::size_t left() const { return bytes_.size() - pos_; }
  std::size_t pos() const { return pos_; }

 private:
  void Need(std::size_t n, const char* what) const {
    if (n > bytes_.size() - pos_)
      throw InputError("fleet message: truncated at byte " + std::to_string(pos_) + " (" + what +
                       " needs " + std::to_string(n) + " bytes, " +
                       std::to_string(bytes_.size() - pos_) + " left)");
  }
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

void CheckSize(std::string_view bytes) {
  if (bytes.size() > kMaxMessageBytes)
    throw InputError("fleet message: " + std::to_string(bytes.size()) + " bytes (at most " +
                     std::to_string(kMaxMessageBytes) + ")");
}

void CheckMagic(Reader* in, const char (&magic)[4], const char* what) {
  const std::string_view m = in->Take(4, "magic");
  if (std::memcmp(m.data(), magic, 4) != 0)
    throw InputError(std::string("fleet message: not a mapless ") + what + " (bad magic)");
  const auto version = in->Get<std::uint8_t>("version");
  if (version != kWireVersion)
    throw InputError("fleet message: wire version " + std::to_string(version) +
                     " (this mapless speaks " + std::to_string(kWireVersion) + ")");
}

}  // namespace

std::int64_t WallClockNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

const char* RecordTypeName(RecordType type) {
  switch (type) {
    case RecordType::kHeader:
      return "header";
    case RecordType::kKeyframe:
      return "keyframe";
    case RecordType::kImage:
      return "image";
    case RecordType::kEnd:
      return "end";
    case RecordType::kHeartbeat:
      return "heartbeat";
    case RecordType::kView:
      return "view";
  }
  return "?";
}

std::string EncodeRecord(const Record& record) {
  MAPLESS_CHECK(record.parts.size() <= kMaxParts,
                "EncodeRecord: " << record.parts.size() << " parts (at most " << kMaxParts << ")");
  std::string out(kRecordMagic, 4);
  Put<std::uint8_t>(&out, kWireVersion);
  Put<std::uint8_t>(&out, static_cast<std::uint8_t>(record.type));
  Put<std::uint16_t>(&out, 0);
  Put<std::uint64_t>(&out, record.sequence);
  Put<std::int64_t>(&out, record.written_ns);
  Put<std::uint32_t>(&out, static_cast<std::uint32_t>(record.parts.size()));
  for (const std::string& part : record.parts) {
    Put<std::uint32_t>(&out, static_cast<std::uint32_t>(part.size()));
    out += part;
  }
  MAPLESS_CHECK(out.size() <= kMaxMessageBytes,
                "EncodeRecord: " << out.size() << " bytes (at most " << kMaxMessageBytes << ")");
  return out;
}

Record DecodeRecord(std::string_view bytes) {
  CheckSize(bytes);
  Reader in(bytes);
  CheckMagic(&in, kRecordMagic, "record");
  Record r;
  const auto type = in.Get<std::uint8_t>("type");
  if (type < static_cast<std::uint8_t>(RecordType::kHeader) ||
      type > static_cast<std::uint8_t>(RecordType::kView))
    throw InputError("fleet message: unknown record type " + std::to_string(type));
  r.type = static_cast<RecordType>(type);
  if (in.Get<std::uint16_t>("reserved") != 0)
    throw InputError("fleet message: reserved bytes are not zero");
  r.sequence = in.Get<std::uint64_t>("sequence");
  if (r.sequence > kMaxSequence)
    throw InputError("fleet message: sequence " + std::to_string(r.sequence) + " (at most " +
                     std::to_string(kMaxSequence) + ")");
  r.written_ns = in.Get<std::int64_t>("written_ns");
  const auto parts = in.Get<std::uint32_t>("part count");
  if (parts > kMaxParts)
    throw InputError("fleet message: " + std::to_string(parts) + " parts (at most " +
                     std::to_string(kMaxParts) + ")");
  for (std::uint32_t i = 0; i < parts; ++i) {
    const auto length = in.Get<std::uint32_t>("part length");
    r.parts.emplace_back(in.Take(length, "part"));
  }
  if (in.left() != 0)
    throw InputError("fleet message: " + std::to_string(in.left()) + " bytes after the last part");
  // The parts each type must have (their contents are checked where they are used).
  const std::size_t expected = r.type == RecordType::kHeader      ? 1
                               : r.type == RecordType::kKeyframe  ? 2
                               : r.type == RecordType::kImage     ? 2
                               : r.type == RecordType::kView      ? 2
                               : r.type == RecordType::kHeartbeat ? 1
                                                                  : 0;
  if (r.parts.size() != expected)
    throw InputError(std::string("fleet message: a ") + RecordTypeName(r.type) + " record has " +
                     std::to_string(r.parts.size()) + " parts (expected " +
                     std::to_string(expected) + ")");
  if (r.type == RecordType::kHeader && r.sequence != 0)
    throw InputError("fleet message: a header record with sequence " + std::to_string(r.sequence) +
                     " (it is always 0)");
  return r;
}

std::string EncodeSubscribe(std::uint64_t from) {
  std::string out(kControlMagic, 4);
  Put<std::uint8_t>(&out, kWireVersion);
  Put<std::uint8_t>(&out, kSubscribeType);
  Put<std::uint16_t>(&out, 0);
  Put<std::uint64_t>(&out, from);
  return out;
}

std::uint64_t DecodeSubscribe(std::string_view bytes) {
  if (bytes.size() != kSubscribeBytes)
    throw InputError("fleet message: a subscription of " + std::to_string(bytes.size()) +
                     " bytes (expected " + std::to_string(kSubscribeBytes) + ")");
  Reader in(bytes);
  CheckMagic(&in, kControlMagic, "subscription");
  if (in.Get<std::uint8_t>("type") != kSubscribeType)
    throw InputError("fleet message: unknown control message type");
  if (in.Get<std::uint16_t>("reserved") != 0)
    throw InputError("fleet message: reserved bytes are not zero");
  const auto from = in.Get<std::uint64_t>("from");
  if (from > kMaxSequence)
    throw InputError("fleet message: from sequence " + std::to_string(from) + " (at most " +
                     std::to_string(kMaxSequence) + ")");
  return from;
}

}  // namespace mapless::fleet
