#include "mapless/recording/mcap_format.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>

#include "mapless/core/check.h"

namespace mapless::recording {

namespace {

// Little-endian fields of one record body, each checked against what is left.
class BodyReader {
 public:
  BodyReader(std::string_view body, const char* record) : s_(body), record_(record) {}

  template <typename T>
  T Int(const char* field) {
    Need(sizeof(T), field);
    T v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v = static_cast<T>(v | (static_cast<T>(static_cast<std::uint8_t>(s_[pos_ + i])) << (8 * i)));
    pos_ += sizeof(T);
    return v;
  }
  std::uint8_t U8(const char* f) { return Int<std::uint8_t>(f); }
  std::uint16_t U16(const char* f) { return Int<std::uint16_t>(f); }
  std::uint32_t U32(const char* f) { return Int<std::uint32_t>(f); }
  std::uint64_t U64(const char* f) { return Int<std::uint64_t>(f); }
  std::string_view Take(std::uint64_t n, const char* field) {
    Need(n, field);
    std::string_view out = s_.substr(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return out;
  }
  std::string Str(const char* field) { return std::string(Take(U32(field), field)); }
  std::string Bytes32(const char* field) { return std::string(Take(U32(field), field)); }
  std::string Bytes64(const char* field) { return std::string(Take(U64(field), field)); }
  std::string Rest() { return std::string(Take(s_.size() - pos_, "data")); }
  StringMap StrMap(const char* field) {
    BodyReader m(Take(U32(field), field), record_);
    StringMap out;
    while (!m.AtEnd()) {
      std::string k = m.Str(field);
      out[k] = m.Str(field);
    }
    return out;
  }
  std::map<std::uint16_t, std::uint64_t> U16U64Map(const char* field) {
    BodyReader m(Take(U32(field), field), record_);
    std::map<std::uint16_t, std::uint64_t> out;
    while (!m.AtEnd()) {
      const std::uint16_t k = m.U16(field);
      out[k] = m.U64(field);
    }
    return out;
  }
  bool AtEnd() const { return pos_ == s_.size(); }

 private:
  void Need(std::uint64_t n, const char* field) const {
    if (n > s_.size() - pos_)
      throw InputError(std::string("MCAP ") + record_ + " record: " + field + " needs " +
                       std::to_string(n) + " bytes, " + std::to_string(s_.size() - pos_) +
                       " are left");
  }
  std::string_view s_;
  const char* record_;
  std::size_t pos_ = 0;
};

class BodyWriter {
 public:
  template <typename T>
  BodyWriter& Int(T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i)
      s_.push_back(static_cast<char>((static_cast<std::uint64_t>(v) >> (8 * i)) & 0xFF));
    return *this;
  }
  BodyWriter& U8(std::uint8_t v) { return Int(v); }
  BodyWriter& U16(std::uint16_t v) { return Int(v); }
  BodyWriter& U32(std::uint32_t v) { return Int(v); }
  BodyWriter& U64(std::uint64_t v) { return Int(v); }
  BodyWriter& Str(std::string_view v) {
    U32(static_cast<std::uint32_t>(v.size()));
    s_.append(v);
    return *this;
  }
  BodyWriter& Bytes64(std::string_view v) {
    U64(v.size());
    s_.append(v);
    return *this;
  }
  BodyWriter& Raw(std::string_view v) {
    s_.append(v);
    return *this;
  }
  BodyWriter& StrMap(const StringMap& m) {
    BodyWriter inner;
    for (const auto& [k, v] : m) inner.Str(k).Str(v);
    return Str(inner.s_);
  }
  BodyWriter& U16U64Map(const std::map<std::uint16_t, std::uint64_t>& m) {
    BodyWriter inner;
    for (const auto& [k, v] : m) inner.U16(k).U64(v);
    return Str(inner.s_);
  }
  // Swapped out rather than moved: GCC 12 warns (-Warray-bounds, a known false positive) about
  // moving a short string out of a temporary.
  std::string Take() {
    std::string out;
    out.swap(s_);
    return out;
  }

 private:
  std::string s_;
};

}  // namespace

const char* McapOpName(std::uint8_t op) {
  static const char* const kNames[] = {
      "Unknown",  "Header",        "Footer",        "Schema",     "Channel",         "Message",
      "Chunk",    "MessageIndex",  "ChunkIndex",    "Attachment", "AttachmentIndex", "Statistics",
      "Metadata", "MetadataIndex", "SummaryOffset", "DataEnd"};
  return op <= 0x0F ? kNames[op] : "Unknown";
}

McapHeader ParseMcapHeader(std::string_view body) {
  BodyReader r(body, "Header");
  McapHeader h;
  h.profile = r.Str("profile");
  h.library = r.Str("library");
  return h;
}
McapFooter ParseMcapFooter(std::string_view body) {
  BodyReader r(body, "Footer");
  McapFooter f;
  f.summary_start = r.U64("summary_start");
  f.summary_offset_start = r.U64("summary_offset_start");
  f.summary_crc = r.U32("summary_crc");
  return f;
}
McapSchema ParseMcapSchema(std::string_view body) {
  BodyReader r(body, "Schema");
  McapSchema s;
  s.id = r.U16("id");
  s.name = r.Str("name");
  s.encoding = r.Str("encoding");
  s.data = r.Bytes32("data");
  return s;
}
McapChannel ParseMcapChannel(std::string_view body) {
  BodyReader r(body, "Channel");
  McapChannel c;
  c.id = r.U16("id");
  c.schema_id = r.U16("schema_id");
  c.topic = r.Str("topic");
  c.message_encoding = r.Str("message_encoding");
  c.metadata = r.StrMap("metadata");
  return c;
}
McapMessage ParseMcapMessage(std::string_view body) {
  BodyReader r(body, "Message");
  McapMessage m;
  m.channel_id = r.U16("channel_id");
  m.sequence = r.U32("sequence");
  m.log_time = r.U64("log_time");
  m.publish_time = r.U64("publish_time");
  m.data = r.Rest();
  return m;
}
McapChunk ParseMcapChunk(std::string_view body) {
  BodyReader r(body, "Chunk");
  McapChunk c;
  c.message_start_time = r.U64("message_start_time");
  c.message_end_time = r.U64("message_end_time");
  c.uncompressed_size = r.U64("uncompressed_size");
  c.uncompressed_crc = r.U32("uncompressed_crc");
  c.compression = r.Str("compression");
  c.records = r.Bytes64("records");
  return c;
}
McapMessageIndex ParseMcapMessageIndex(std::string_view body) {
  BodyReader r(body, "MessageIndex");
  McapMessageIndex m;
  m.channel_id = r.U16("channel_id");
  BodyReader entries(r.Take(r.U32("records"), "records"), "MessageIndex");
  while (!entries.AtEnd()) {
    const std::uint64_t t = entries.U64("records");
    m.records.emplace_back(t, entries.U64("records"));
  }
  return m;
}
McapChunkIndex ParseMcapChunkIndex(std::string_view body) {
  BodyReader r(body, "ChunkIndex");
  McapChunkIndex c;
  c.message_start_time = r.U64("message_start_time");
  c.message_end_time = r.U64("message_end_time");
  c.chunk_start_offset = r.U64("chunk_start_offset");
  c.chunk_length = r.U64("chunk_length");
  c.message_index_offsets = r.U16U64Map("message_index_offsets");
  c.message_index_length = r.U64("message_index_length");
  c.compression = r.Str("compression");
  c.compressed_size = r.U64("compressed_size");
  c.uncompressed_size = r.U64("uncompressed_size");
  return c;
}
McapAttachment ParseMcapAttachment(std::string_view body) {
  BodyReader r(body, "Attachment");
  McapAttachment a;
  a.log_time = r.U64("log_time");
  a.create_time = r.U64("create_time");
  a.name = r.Str("name");
  a.media_type = r.Str("media_type");
  a.data = r.Bytes64("data");
  a.crc = r.U32("crc");
  return a;
}
McapAttachmentIndex ParseMcapAttachmentIndex(std::string_view body) {
  BodyReader r(body, "AttachmentIndex");
  McapAttachmentIndex a;
  a.offset = r.U64("offset");
  a.length = r.U64("length");
  a.log_time = r.U64("log_time");
  a.create_time = r.U64("create_time");
  a.data_size = r.U64("data_size");
  a.name = r.Str("name");
  a.media_type = r.Str("media_type");
  return a;
}
McapStatistics ParseMcapStatistics(std::string_view body) {
  BodyReader r(body, "Statistics");
  McapStatistics s;
  s.message_count = r.U64("message_count");
  s.schema_count = r.U16("schema_count");
  s.channel_count = r.U32("channel_count");
  s.attachment_count = r.U32("attachment_count");
  s.metadata_count = r.U32("metadata_count");
  s.chunk_count = r.U32("chunk_count");
  s.message_start_time = r.U64("message_start_time");
  s.message_end_time = r.U64("message_end_time");
  s.channel_message_counts = r.U16U64Map("channel_message_counts");
  return s;
}
McapMetadata ParseMcapMetadata(std::string_view body) {
  BodyReader r(body, "Metadata");
  McapMetadata m;
  m.name = r.Str("name");
  m.metadata = r.StrMap("metadata");
  return m;
}
McapMetadataIndex ParseMcapMetadataIndex(std::string_view body) {
  BodyReader r(body, "MetadataIndex");
  McapMetadataIndex m;
  m.offset = r.U64("offset");
  m.length = r.U64("length");
  m.name = r.Str("name");
  return m;
}
McapSummaryOffset ParseMcapSummaryOffset(std::string_view body) {
  BodyReader r(body, "SummaryOffset");
  McapSummaryOffset s;
  s.group_opcode = r.U8("group_opcode");
  s.group_start = r.U64("group_start");
  s.group_length = r.U64("group_length");
  return s;
}
McapDataEnd ParseMcapDataEnd(std::string_view body) {
  BodyReader r(body, "DataEnd");
  McapDataEnd d;
  d.data_section_crc = r.U32("data_section_crc");
  return d;
}

void AppendMcapRecord(McapOp op, std::string_view body, std::string* out) {
  BodyWriter w;
  w.U8(static_cast<std::uint8_t>(op)).U64(body.size());
  out->append(w.Take());
  out->append(body);
}

std::string McapBody(const McapHeader& r) {
  return BodyWriter().Str(r.profile).Str(r.library).Take();
}
std::string McapBody(const McapFooter& r) {
  return BodyWriter().U64(r.summary_start).U64(r.summary_offset_start).U32(r.summary_crc).Take();
}
std::string McapBody(const McapSchema& r) {
  return BodyWriter().U16(r.id).Str(r.name).Str(r.encoding).Str(r.data).Take();
}
std::string McapBody(const McapChannel& r) {
  return BodyWriter()
      .U16(r.id)
      .U16(r.schema_id)
      .Str(r.topic)
      .Str(r.message_encoding)
      .StrMap(r.metadata)
      .Take();
}
std::string McapBody(const McapMessage& r) {
  return BodyWriter()
      .U16(r.channel_id)
      .U32(r.sequence)
      .U64(r.log_time)
      .U64(r.publish_time)
      .Raw(r.data)
      .Take();
}
std::string McapBody(const McapChunk& r) {
  return BodyWriter()
      .U64(r.message_start_time)
      .U64(r.message_end_time)
      .U64(r.uncompressed_size)
      .U32(r.uncompressed_crc)
      .Str(r.compression)
      .Bytes64(r.records)
      .Take();
}
std::string McapBody(const McapMessageIndex& r) {
  BodyWriter entries;
  for (const auto& [t, offset] : r.records) entries.U64(t).U64(offset);
  return BodyWriter().U16(r.channel_id).Str(entries.Take()).Take();
}
std::string McapBody(const McapChunkIndex& r) {
  return BodyWriter()
      .U64(r.message_start_time)
      .U64(r.message_end_time)
      .U64(r.chunk_start_offset)
      .U64(r.chunk_length)
      .U16U64Map(r.message_index_offsets)
      .U64(r.message_index_length)
      .Str(r.compression)
      .U64(r.compressed_size)
      .U64(r.uncompressed_size)
      .Take();
}
std::string McapBody(const McapAttachment& r) {
  return BodyWriter()
      .U64(r.log_time)
      .U64(r.create_time)
      .Str(r.name)
      .Str(r.media_type)
      .Bytes64(r.data)
      .U32(r.crc)
      .Take();
}
std::string McapBody(const McapAttachmentIndex& r) {
  return BodyWriter()
      .U64(r.offset)
      .U64(r.length)
      .U64(r.log_time)
      .U64(r.create_time)
      .U64(r.data_size)
      .Str(r.name)
      .Str(r.media_type)
      .Take();
}
std::string McapBody(const McapStatistics& r) {
  return BodyWriter()
      .U64(r.message_count)
      .U16(r.schema_count)
      .U32(r.channel_count)
      .U32(r.attachment_count)
      .U32(r.metadata_count)
      .U32(r.chunk_count)
      .U64(r.message_start_time)
      .U64(r.message_end_time)
      .U16U64Map(r.channel_message_counts)
      .Take();
}
std::string McapBody(const McapMetadata& r) {
  return BodyWriter().Str(r.name).StrMap(r.metadata).Take();
}
std::string McapBody(const McapMetadataIndex& r) {
  return BodyWriter().U64(r.offset).U64(r.length).Str(r.name).Take();
}
std::string McapBody(const McapSummaryOffset& r) {
  return BodyWriter().U8(r.group_opcode).U64(r.group_start).U64(r.group_length).Take();
}
std::string McapBody(const McapDataEnd& r) { return BodyWriter().U32(r.data_section_crc).Take(); }

bool McapRecordCursor::Next(std::uint8_t* op, std::string_view* body) {
  if (pos_ >= bytes_.size() || cut_) return false;
  constexpr std::size_t kPrefix = 9;  // opcode, u64 length
  if (bytes_.size() - pos_ < kPrefix) {
    if (tolerate_cut_) {
      cut_ = true;
      return false;
    }
    throw InputError("MCAP: a record at byte " + std::to_string(offset()) + " is cut short (" +
                     std::to_string(bytes_.size() - pos_) + " bytes left, its prefix needs 9)");
  }
  BodyReader prefix(bytes_.substr(pos_, kPrefix), "record");
  *op = prefix.U8("opcode");
  const std::uint64_t length = prefix.U64("length");
  if (length > bytes_.size() - pos_ - kPrefix) {
    // A recording whose writer stopped ends inside its last record, whose length is what the
    // writer meant to write: a length beyond any record's (4 GiB) is a corrupt file, not a cut.
    if (length > kMaxPlausibleRecordBytes) {
      throw InputError(std::string("MCAP: ") + McapOpName(*op) + " record at byte " +
                       std::to_string(offset()) + " says " + std::to_string(length) +
                       " bytes: not a record length (the file is corrupt)");
    }
    if (tolerate_cut_) {
      cut_ = true;
      return false;
    }
    throw InputError(std::string("MCAP: ") + McapOpName(*op) + " record at byte " +
                     std::to_string(offset()) + " says " + std::to_string(length) +
                     " bytes, only " + std::to_string(bytes_.size() - pos_ - kPrefix) +
                     " are left");
  }
  *body = bytes_.substr(pos_ + kPrefix, static_cast<std::size_t>(length));
  pos_ += kPrefix + static_cast<std::size_t>(length);
  return true;
}

std::uint32_t McapCrc32(std::string_view bytes, std::uint32_t crc) {
  // zlib takes uInt lengths: feed large ranges in pieces.
  uLong c = crc;
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);
    c = ::crc32(c, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(n));
    bytes.remove_prefix(n);
  }
  return static_cast<std::uint32_t>(c);
}

}  // namespace mapless::recording
