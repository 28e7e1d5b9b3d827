// The MCAP format's own conformance inputs (foxglove/mcap tests/conformance; tests/data/
// mcap_conformance/README.md): 416 files in every layout, each with the records a reader must
// return. Upstream keeps the files in Git LFS, so only their SHA-256 and size are here. Each file
// is rebuilt from its input records and layout features as upstream's generate-inputs.ts writes
// it; the SHA-256 and size must be the pointer's (then these are upstream's bytes, whoever built
// them), and mapless's reader must return exactly the expected records.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#ifdef MAPLESS_HAVE_SODIUM
#include <sodium.h>
#endif

#include "mapless/io/atomic_file.h"
#include "mapless/recording/mcap_format.h"
#include "mapless/recording/mcap_reader.h"

namespace mapless::recording {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A record of the expectations: its fields by name.
std::map<std::string, json> Fields(const json& record) {
  std::map<std::string, json> out;
  for (const json& pair : record.at("fields")) out[pair.at(0).get<std::string>()] = pair.at(1);
  return out;
}
std::uint64_t U(const json& j) { return std::stoull(j.get<std::string>()); }
std::string Bytes(const json& j) {
  std::string out;
  for (const json& b : j) out.push_back(static_cast<char>(std::stoi(b.get<std::string>())));
  return out;
}
StringMap Strings(const json& j) {
  StringMap out;
  for (const auto& [k, v] : j.items()) out[k] = v.get<std::string>();
  return out;
}

// The record as upstream's toSerializableMcapRecord writes it: fields sorted by name, numbers as
// strings, bytes as lists of decimal strings, maps as objects.
json Record(const std::string& type, const std::map<std::string, json>& fields) {
  json out{{"type", type}, {"fields", json::array()}};
  for (const auto& [k, v] : fields) out["fields"].push_back(json::array({k, v}));
  return out;
}
json S(std::uint64_t v) { return std::to_string(v); }
json B(const std::string& bytes) {
  json out = json::array();
  for (unsigned char c : bytes) out.push_back(std::to_string(c));
  return out;
}
json M(const StringMap& m) {
  json out = json::object();
  for (const auto& [k, v] : m) out[k] = v;
  return out;
}
json M(const std::map<std::uint16_t, std::uint64_t>& m) {
  json out = json::object();
  for (const auto& [k, v] : m) out[std::to_string(k)] = std::to_string(v);
  return out;
}

// Every record mapless's reader returns, as the expectations list them (message indexes are left
// out, as upstream's streamed readers do).
json ReadAll(McapReader& reader) {
  json out = json::array();
  reader.ForEachRecord([&](std::uint8_t op, std::string_view body, std::uint64_t) {
    switch (static_cast<McapOp>(op)) {
      case McapOp::kHeader: {
        const McapHeader r = ParseMcapHeader(body);
        out.push_back(Record("Header", {{"library", r.library}, {"profile", r.profile}}));
        break;
      }
      case McapOp::kFooter: {
        const McapFooter r = ParseMcapFooter(body);
        out.push_back(Record("Footer", {{"summary_crc", S(r.summary_crc)},
                                        {"summary_offset_start", S(r.summary_offset_start)},
                                        {"summary_start", S(r.summary_start)}}));
        break;
      }
      case McapOp::kSchema: {
        const McapSchema r = ParseMcapSchema(body);
        out.push_back(Record(
            "Schema",
            {{"data", B(r.data)}, {"encoding", r.encoding}, {"id", S(r.id)}, {"name", r.name}}));
        break;
      }
      case McapOp::kChannel: {
        const McapChannel r = ParseMcapChannel(body);
        out.push_back(Record("Channel", {{"id", S(r.id)},
                                         {"message_encoding", r.message_encoding},
                                         {"metadata", M(r.metadata)},
                                         {"schema_id", S(r.schema_id)},
                                         {"topic", r.topic}}));
        break;
      }
      case McapOp::kMessage: {
        const McapMessage r = ParseMcapMessage(body);
        out.push_back(Record("Message", {{"channel_id", S(r.channel_id)},
                                         {"data", B(r.data)},
                                         {"log_time", S(r.log_time)},
                                         {"publish_time", S(r.publish_time)},
                                         {"sequence", S(r.sequence)}}));
        break;
      }
      case McapOp::kChunkIndex: {
        const McapChunkIndex r = ParseMcapChunkIndex(body);
        out.push_back(Record("ChunkIndex", {{"chunk_length", S(r.chunk_length)},
                                            {"chunk_start_offset", S(r.chunk_start_offset)},
                                            {"compressed_size", S(r.compressed_size)},
                                            {"compression", r.compression},
                                            {"message_end_time", S(r.message_end_time)},
                                            {"message_index_length", S(r.message_index_length)},
                                            {"message_index_offsets", M(r.message_index_offsets)},
                                            {"message_start_time", S(r.message_start_time)},
                                            {"uncompressed_size", S(r.uncompressed_size)}}));
        break;
      }
      case McapOp::kAttachment: {
        const McapAttachment r = ParseMcapAttachment(body);
        out.push_back(Record("Attachment", {{"create_time", S(r.create_time)},
                                            {"data", B(r.data)},
                                            {"log_time", S(r.log_time)},
                                            {"media_type", r.media_type},
                                            {"name", r.name}}));
        break;
      }
      case McapOp::kAttachmentIndex: {
        const McapAttachmentIndex r = ParseMcapAttachmentIndex(body);
        out.push_back(Record("AttachmentIndex", {{"create_time", S(r.create_time)},
                                                 {"data_size", S(r.data_size)},
                                                 {"length", S(r.length)},
                                                 {"log_time", S(r.log_time)},
                                                 {"media_type", r.media_type},
                                                 {"name", r.name},
                                                 {"offset", S(r.offset)}}));
        break;
      }
      case McapOp::kStatistics: {
        const McapStatistics r = ParseMcapStatistics(body);
        out.push_back(Record("Statistics", {{"attachment_count", S(r.attachment_count)},
                                            {"channel_count", S(r.channel_count)},
                                            {"channel_message_counts", M(r.channel_message_counts)},
                                            {"chunk_count", S(r.chunk_count)},
                                            {"message_count", S(r.message_count)},
                                            {"message_end_time", S(r.message_end_time)},
                                            {"message_start_time", S(r.message_start_time)},
                                            {"metadata_count", S(r.metadata_count)},
                                            {"schema_count", S(r.schema_count)}}));
        break;
      }
      case McapOp::kMetadata: {
        const McapMetadata r = ParseMcapMetadata(body);
        out.push_back(Record("Metadata", {{"metadata", M(r.metadata)}, {"name", r.name}}));
        break;
      }
      case McapOp::kMetadataIndex: {
        const McapMetadataIndex r = ParseMcapMetadataIndex(body);
        out.push_back(Record("MetadataIndex",
                             {{"length", S(r.length)}, {"name", r.name}, {"offset", S(r.offset)}}));
        break;
      }
      case McapOp::kSummaryOffset: {
        const McapSummaryOffset r = ParseMcapSummaryOffset(body);
        out.push_back(Record("SummaryOffset", {{"group_length", S(r.group_length)},
                                               {"group_opcode", S(r.group_opcode)},
                                               {"group_start", S(r.group_start)}}));
        break;
      }
      case McapOp::kDataEnd:
        out.push_back(
            Record("DataEnd", {{"data_section_crc", S(ParseMcapDataEnd(body).data_section_crc)}}));
        break;
      default:  // chunks come as their records; message indexes are left out
        break;
    }
  });
  return out;
}

// The file's bytes from its input records (the expectations' data section) and layout features,
// record for record as upstream's generate-inputs.ts (with @mcap/core's McapRecordBuilder and
// ChunkBuilder) writes them: one uncompressed chunk of every schema, channel and message;
// attachments and metadata outside it; "pad" adds 01 ff ff to every record that may be padded
// (not messages, chunks, data end or footer, nor the records inside the chunk).
std::string Build(const std::set<std::string>& features, const json& expected) {
  const auto has = [&](const char* f) { return features.count(f) > 0; };
  const bool pad = has("pad");
  std::string out(kMcapMagic);
  const auto append = [&](McapOp op, std::string body, bool padded, std::string* to) {
    if (padded && pad) body += "\x01\xff\xff";
    AppendMcapRecord(op, body, to);
  };
  append(McapOp::kHeader, McapBody(McapHeader{}), true, &out);
  const bool chunked = has("ch");
  std::string chunk;
  std::vector<std::pair<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>>>
      indexes;  // in the order the channels came (a Map in JS)
  const auto index_of = [&](std::uint16_t channel) -> auto& {
    for (auto& i : indexes)
      if (i.first == channel) return i.second;
    indexes.push_back({channel, {}});
    return indexes.back().second;
  };
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  McapStatistics stats;
  bool any_message = false;
  std::uint64_t chunk_start_time = 0, chunk_end_time = 0;
  std::vector<std::string> attachment_indexes, metadata_indexes, chunk_indexes;
  for (const json& record : expected.at("records")) {
    const std::string type = record.at("type");
    if (type == "DataEnd") break;
    const auto f = Fields(record);
    if (type == "Schema") {
      McapSchema r{static_cast<std::uint16_t>(U(f.at("id"))), f.at("name"), f.at("encoding"),
                   Bytes(f.at("data"))};
      schemas.push_back(r);
      ++stats.schema_count;
      chunked ? append(McapOp::kSchema, McapBody(r), false, &chunk)
              : append(McapOp::kSchema, McapBody(r), true, &out);
    } else if (type == "Channel") {
      McapChannel r{static_cast<std::uint16_t>(U(f.at("id"))),
                    static_cast<std::uint16_t>(U(f.at("schema_id"))), f.at("topic"),
                    f.at("message_encoding"), Strings(f.at("metadata"))};
      channels.push_back(r);
      ++stats.channel_count;
      if (chunked && has("mx")) index_of(r.id);
      chunked ? append(McapOp::kChannel, McapBody(r), false, &chunk)
              : append(McapOp::kChannel, McapBody(r), true, &out);
    } else if (type == "Message") {
      McapMessage r{static_cast<std::uint16_t>(U(f.at("channel_id"))),
                    static_cast<std::uint32_t>(U(f.at("sequence"))), U(f.at("log_time")),
                    U(f.at("publish_time")), Bytes(f.at("data"))};
      if (!any_message || r.log_time < stats.message_start_time)
        stats.message_start_time = r.log_time;
      if (!any_message || r.log_time > stats.message_end_time) stats.message_end_time = r.log_time;
      ++stats.message_count;
      ++stats.channel_message_counts[r.channel_id];
      if (chunked) {
        if (!any_message || r.log_time < chunk_start_time) chunk_start_time = r.log_time;
        if (!any_message || r.log_time > chunk_end_time) chunk_end_time = r.log_time;
        if (has("mx")) index_of(r.channel_id).push_back({r.log_time, chunk.size()});
        append(McapOp::kMessage, McapBody(r), false, &chunk);
      } else {
        append(McapOp::kMessage, McapBody(r), false, &out);
      }
      any_message = true;
    } else if (type == "Attachment") {
      McapAttachment r{U(f.at("log_time")), U(f.at("create_time")), f.at("name"),
                       f.at("media_type"),  Bytes(f.at("data")),    0};
      std::string body = McapBody(r);
      r.crc = McapCrc32(std::string_view(body).substr(0, body.size() - 4));
      ++stats.attachment_count;
      const std::uint64_t offset = out.size();
      append(McapOp::kAttachment, McapBody(r), true, &out);
      if (has("ax")) {
        attachment_indexes.push_back(
            McapBody(McapAttachmentIndex{offset, out.size() - offset, r.log_time, r.create_time,
                                         r.data.size(), r.name, r.media_type}));
      }
    } else if (type == "Metadata") {
      McapMetadata r{f.at("name"), Strings(f.at("metadata"))};
      ++stats.metadata_count;
      const std::uint64_t offset = out.size();
      append(McapOp::kMetadata, McapBody(r), true, &out);
      if (has("mdx"))
        metadata_indexes.push_back(
            McapBody(McapMetadataIndex{offset, out.size() - offset, r.name}));
    }
  }
  if (chunked) {
    stats.chunk_count = 1;
    const std::uint64_t start = out.size();
    append(McapOp::kChunk,
           McapBody(McapChunk{chunk_start_time, chunk_end_time, chunk.size(), McapCrc32(chunk), "",
                              chunk}),
           false, &out);
    McapChunkIndex ci{chunk_start_time, chunk_end_time, start, out.size() - start, {}, 0, "",
                      chunk.size(),     chunk.size()};
    for (const auto& [channel, records] : indexes) {
      ci.message_index_offsets[channel] = out.size();
      const std::size_t before = out.size();
      append(McapOp::kMessageIndex, McapBody(McapMessageIndex{channel, records}), true, &out);
      ci.message_index_length += out.size() - before;
    }
    if (has("chx")) chunk_indexes.push_back(McapBody(ci));
  }
  append(McapOp::kDataEnd, McapBody(McapDataEnd{McapCrc32(out)}), false, &out);

  const std::uint64_t summary_start = out.size();
  std::vector<McapSummaryOffset> offsets;
  const auto group = [&](McapOp op, const std::function<void()>& write) {
    const std::uint64_t start = out.size();
    write();
    if (out.size() != start)
      offsets.push_back({static_cast<std::uint8_t>(op), start, out.size() - start});
  };
  group(McapOp::kSchema, [&] {
    if (has("rsh"))
      for (const auto& s : schemas) append(McapOp::kSchema, McapBody(s), true, &out);
  });
  group(McapOp::kChannel, [&] {
    if (has("rch"))
      for (const auto& c : channels) append(McapOp::kChannel, McapBody(c), true, &out);
  });
  group(McapOp::kStatistics, [&] {
    if (has("st")) append(McapOp::kStatistics, McapBody(stats), true, &out);
  });
  group(McapOp::kMetadataIndex, [&] {
    for (const auto& b : metadata_indexes) append(McapOp::kMetadataIndex, b, true, &out);
  });
  group(McapOp::kAttachmentIndex, [&] {
    for (const auto& b : attachment_indexes) append(McapOp::kAttachmentIndex, b, true, &out);
  });
  group(McapOp::kChunkIndex, [&] {
    for (const auto& b : chunk_indexes) append(McapOp::kChunkIndex, b, true, &out);
  });
  const bool has_summary = out.size() != summary_start;
  std::uint64_t summary_offset_start = 0;
  if (has("sum")) {
    summary_offset_start = out.size();
    for (const auto& o : offsets) append(McapOp::kSummaryOffset, McapBody(o), true, &out);
  }
  McapFooter footer{has_summary ? summary_start : 0, summary_offset_start, 0};
  std::string footer_record;
  AppendMcapRecord(McapOp::kFooter, McapBody(footer), &footer_record);
  footer.summary_crc = McapCrc32(footer_record.substr(0, 1 + 8 + 8 + 8),
                                 McapCrc32(std::string_view(out).substr(summary_start)));
  AppendMcapRecord(McapOp::kFooter, McapBody(footer), &out);
  out += kMcapMagic;
  return out;
}

#ifdef MAPLESS_HAVE_SODIUM
std::string Sha256Hex(const std::string& bytes) {
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  static const char* kHex = "0123456789abcdef";
  std::string out;
  for (unsigned char c : digest) out += {kHex[c >> 4], kHex[c & 15]};
  return out;
}
#endif

// "version https://git-lfs.github.com/spec/v1\noid sha256:HEX\nsize N\n" -> (HEX, N).
std::pair<std::string, std::uint64_t> LfsPointer(const std::string& text) {
  std::istringstream in(text);
  std::string line, oid;
  std::uint64_t size = 0;
  while (std::getline(in, line)) {
    if (line.rfind("oid sha256:", 0) == 0) oid = line.substr(11);
    if (line.rfind("size ", 0) == 0) size = std::stoull(line.substr(5));
  }
  return {oid, size};
}

TEST(McapConformance, EveryInputIsUpstreamsFileAndReadsToTheExpectedRecords) {
  const fs::path root = fs::path(MAPLESS_SOURCE_DIR) / "tests/data/mcap_conformance";
  ASSERT_TRUE(fs::is_directory(root)) << root;
  int files = 0, identical = 0;
  std::map<std::string, int> per_input;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().filename().string());
      const json expected = json::parse(io::ReadFile(entry.path().string(), 1 << 20));
      // "TenMessages-ch-chx-mx" -> {ch, chx, mx}
      std::set<std::string> features;
      std::stringstream name(entry.path().stem().string());
      std::string part;
      std::getline(name, part, '-');
      while (std::getline(name, part, '-')) features.insert(part);
      const std::string bytes = Build(features, expected);

      fs::path mcap = entry.path();
      mcap.replace_extension(".mcap");
      const std::string stored = io::ReadFile(mcap.string(), 1 << 20);
      if (stored.rfind("version https://git-lfs", 0) == 0) {
        const auto [oid, size] = LfsPointer(stored);
        EXPECT_EQ(bytes.size(), size);
#ifdef MAPLESS_HAVE_SODIUM
        EXPECT_EQ(Sha256Hex(bytes), oid);
        identical += Sha256Hex(bytes) == oid && bytes.size() == size;
#endif
      } else {
        EXPECT_EQ(bytes, stored);  // the real file
        identical += bytes == stored;
      }
      const auto reader = McapReader::FromBytes(bytes, mcap.string());
      const json got = ReadAll(*reader);
      EXPECT_EQ(got, expected.at("records")) << "got " << got.dump();
      // The messages again through the reader's message interface.
      int expected_messages = 0, messages = 0;
      for (const json& r : expected.at("records")) expected_messages += r.at("type") == "Message";
      McapReader::FromBytes(bytes, mcap.string())
          ->ForEachMessage(
              [&](const McapChannel&, const McapSchema*, const McapMessage&) { ++messages; });
      EXPECT_EQ(messages, expected_messages);
      ++files;
      ++per_input[dir.path().filename().string()];
    }
  }
  EXPECT_EQ(files, 416);
  EXPECT_EQ(per_input.size(), 6u);
#ifdef MAPLESS_HAVE_SODIUM
  EXPECT_EQ(identical, files) << "files whose rebuilt bytes are not upstream's";
#else
  GTEST_SKIP() << "the records were checked; the bytes' SHA-256 needs libsodium "
                  "(scripts/setup.sh --ros)";
#endif
}

}  // namespace
}  // namespace mapless::recording
