// The MCAP container format (https://mcap.dev/spec, version 0): its records, as bytes and back.
// Pure functions, no files: mcap_writer.h and mcap_reader.h do the I/O. Every parser checks each
// length against the bytes it was given and throws InputError naming the record and field; nothing
// here trusts a length it read.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace mapless::recording {

// "\x89MCAP0\r\n": the first and last 8 bytes of every MCAP file.
inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

enum class McapOp : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};
// "Header", "Message", ...; "Unknown" for opcodes the spec does not define (readers skip them).
const char* McapOpName(std::uint8_t op);

using StringMap = std::map<std::string, std::string>;

struct McapHeader {
  std::string profile;
  std::string library;
};
struct McapFooter {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};
struct McapSchema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::string data;
};
struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  StringMap metadata;
};
struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::string data;
};
struct McapChunk {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
  std::string records;  // compressed
};
struct McapMessageIndex {
  std::uint16_t channel_id = 0;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> records;  // (log_time, offset in chunk)
};
struct McapChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};
struct McapAttachment {
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::string name;
  std::string media_type;
  std::string data;
  std::uint32_t crc = 0;
};
struct McapAttachmentIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::uint64_t data_size = 0;
  std::string name;
  std::string media_type;
};
struct McapStatistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};
struct McapMetadata {
  std::string name;
  StringMap metadata;
};
struct McapMetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};
struct McapSummaryOffset {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
};
struct McapDataEnd {
  std::uint32_t data_section_crc = 0;
};

// A record's body (without its opcode and length). Extra bytes after the last field are allowed
// (the spec's forward compatibility) and ignored.
McapHeader ParseMcapHeader(std::string_view body);
McapFooter ParseMcapFooter(std::string_view body);
McapSchema ParseMcapSchema(std::string_view body);
McapChannel ParseMcapChannel(std::string_view body);
McapMessage ParseMcapMessage(std::string_view body);
McapChunk ParseMcapChunk(std::string_view body);
McapMessageIndex ParseMcapMessageIndex(std::string_view body);
McapChunkIndex ParseMcapChunkIndex(std::string_view body);
McapAttachment ParseMcapAttachment(std::string_view body);
McapAttachmentIndex ParseMcapAttachmentIndex(std::string_view body);
McapStatistics ParseMcapStatistics(std::string_view body);
McapMetadata ParseMcapMetadata(std::string_view body);
McapMetadataIndex ParseMcapMetadataIndex(std::string_view body);
McapSummaryOffset ParseMcapSummaryOffset(std::string_view body);
McapDataEnd ParseMcapDataEnd(std::string_view body);

// Whole records (opcode, length, body), appended to `out`.
void AppendMcapRecord(McapOp op, std::string_view body, std::string* out);
std::string McapBody(const McapHeader& r);
std::string McapBody(const McapFooter& r);
std::string McapBody(const McapSchema& r);
std::string McapBody(const McapChannel& r);
std::string McapBody(const McapMessage& r);
std::string McapBody(const McapChunk& r);
std::string McapBody(const McapMessageIndex& r);
std::string McapBody(const McapChunkIndex& r);
std::string McapBody(const McapAttachment& r);
std::string McapBody(const McapAttachmentIndex& r);
std::string McapBody(const McapStatistics& r);
std::string McapBody(const McapMetadata& r);
std::string McapBody(const McapMetadataIndex& r);
std::string McapBody(const McapSummaryOffset& r);
std::string McapBody(const McapDataEnd& r);

// One record of a byte range: its opcode and body. `Next` returns false at the end of the range;
// a record longer than kMaxPlausibleRecordBytes always throws InputError (a corrupt length, not a
// cut); a record cut short (its length runs past the end) throws InputError unless `tolerate_cut`,
// when it ends the range too (cut() then says so).
inline constexpr std::uint64_t kMaxPlausibleRecordBytes = std::uint64_t{1} << 32;

class McapRecordCursor {
 public:
  McapRecordCursor(std::string_view bytes, std::uint64_t base_offset, bool tolerate_cut = false)
      : bytes_(bytes), base_(base_offset), tolerate_cut_(tolerate_cut) {}
  bool Next(std::uint8_t* op, std::string_view* body);
  std::uint64_t offset() const { return base_ + pos_; }  // of the next record
  bool cut() const { return cut_; }

 private:
  std::string_view bytes_;
  std::uint64_t base_ = 0;
  bool tolerate_cut_ = false;
  std::size_t pos_ = 0;
  bool cut_ = false;
};

// The CRC-32 MCAP uses (IEEE 802.3, as zlib's crc32), continued from `crc`.
std::uint32_t McapCrc32(std::string_view bytes, std::uint32_t crc = 0);

}  // namespace mapless::recording
