#include "mapless/recording/mcap_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>

#include "mapless/core/check.h"
#include "mapless/recording/compression.h"

namespace mapless::recording {

McapWriter::McapWriter(const std::string& path, const McapWriterOptions& options)
    : path_(path), options_(options) {
  CheckCompression(options.compression);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError(path + ": cannot create the recording: " + std::strerror(errno) +
                     (errno == EEXIST ? " (mapless does not overwrite a recording)" : ""));
  Append(kMcapMagic);
  std::string header;
  AppendMcapRecord(McapOp::kHeader, McapBody(McapHeader{options.profile, options.library}),
                   &header);
  Append(header);
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const std::exception&) {
    // Close() in a destructor cannot report; the chunks written so far stay readable.
  }
  if (fd_ >= 0) ::close(fd_);
}

void McapWriter::Append(std::string_view bytes) {
  data_crc_ = McapCrc32(bytes, data_crc_);
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw InputError(path_ + ": cannot write the recording: " + std::strerror(errno));
    bytes.remove_prefix(static_cast<std::size_t>(n));
    offset_ += static_cast<std::uint64_t>(n);
  }
}

std::uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding,
                                    const std::string& data) {
  MAPLESS_CHECK(schemas_.size() < std::numeric_limits<std::uint16_t>::max() - 1,
                path_ << ": too many schemas");
  McapSchema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  std::string record;
  AppendMcapRecord(McapOp::kSchema, McapBody(s), &record);
  Append(record);
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t McapWriter::AddChannel(std::uint16_t schema_id, const std::string& topic,
                                     const std::string& message_encoding,
                                     const StringMap& metadata) {
  MAPLESS_CHECK(schema_id <= schemas_.size(),
                path_ << ": channel " << topic << ": no schema " << schema_id);
  MAPLESS_CHECK(channels_.size() < std::numeric_limits<std::uint16_t>::max() - 1,
                path_ << ": too many channels");
  McapChannel c{static_cast<std::uint16_t>(channels_.size() + 1), schema_id, topic,
                message_encoding, metadata};
  std::string record;
  AppendMcapRecord(McapOp::kChannel, McapBody(c), &record);
  Append(record);
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

void McapWriter::Write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                       std::string_view data) {
  MAPLESS_CHECK(!closed_, path_ << ": a message after the recording was closed");
  MAPLESS_CHECK(channel_id >= 1 && channel_id <= channels_.size(),
                path_ << ": no channel " << channel_id);
  if (!chunk_.empty() && log_time >= chunk_start_ && log_time - chunk_start_ > options_.chunk_ns)
    WriteChunk();
  if (chunk_.empty()) chunk_start_ = chunk_end_ = log_time;
  chunk_start_ = std::min(chunk_start_, log_time);
  chunk_end_ = std::max(chunk_end_, log_time);
  McapMessage m;
  m.channel_id = channel_id;
  m.sequence = sequence_[channel_id]++;
  m.log_time = log_time;
  m.publish_time = publish_time;
  m.data = std::string(data);
  McapMessageIndex& index = chunk_index_[channel_id];
  index.channel_id = channel_id;
  index.records.emplace_back(log_time, chunk_.size());
  AppendMcapRecord(McapOp::kMessage, McapBody(m), &chunk_);
  if (stats_.message_count == 0 || log_time < stats_.message_start_time)
    stats_.message_start_time = log_time;
  stats_.message_end_time = std::max(stats_.message_end_time, log_time);
  ++stats_.message_count;
  ++stats_.channel_message_counts[channel_id];
  if (chunk_.size() >= options_.chunk_bytes) WriteChunk();
}

void McapWriter::WriteChunk() {
  if (chunk_.empty()) return;
  McapChunk chunk;
  chunk.message_start_time = chunk_start_;
  chunk.message_end_time = chunk_end_;
  chunk.uncompressed_size = chunk_.size();
  chunk.uncompressed_crc = McapCrc32(chunk_);
  chunk.compression = options_.compression;
  chunk.records = Compress(options_.compression, chunk_);
  McapChunkIndex index;
  index.message_start_time = chunk_start_;
  index.message_end_time = chunk_end_;
  index.chunk_start_offset = offset_;
  index.compression = options_.compression;
  index.compressed_size = chunk.records.size();
  index.uncompressed_size = chunk_.size();
  std::string out;
  AppendMcapRecord(McapOp::kChunk, McapBody(chunk), &out);
  index.chunk_length = out.size();
  for (const auto& [channel, message_index] : chunk_index_) {
    index.message_index_offsets[channel] = offset_ + out.size();
    AppendMcapRecord(McapOp::kMessageIndex, McapBody(message_index), &out);
  }
  index.message_index_length = out.size() - index.chunk_length;
  Append(out);
  chunk_indexes_.push_back(std::move(index));
  ++stats_.chunk_count;
  chunk_.clear();
  chunk_index_.clear();
}

void McapWriter::Flush() { WriteChunk(); }

void McapWriter::Close() {
  if (closed_ || fd_ < 0) return;
  closed_ = true;
  WriteChunk();
  std::string data_end;
  AppendMcapRecord(McapOp::kDataEnd, McapBody(McapDataEnd{data_crc_}), &data_end);
  Append(data_end);
  // The summary: groups of records, each listed by a summary offset.
  const std::uint64_t summary_start = offset_;
  std::string summary;
  std::vector<McapSummaryOffset> groups;
  const auto group = [&](McapOp op, auto&& write) {
    const std::size_t start = summary.size();
    write();
    if (summary.size() > start)
      groups.push_back(
          {static_cast<std::uint8_t>(op), summary_start + start, summary.size() - start});
  };
  group(McapOp::kSchema, [&] {
    for (const McapSchema& s : schemas_) AppendMcapRecord(McapOp::kSchema, McapBody(s), &summary);
  });
  group(McapOp::kChannel, [&] {
    for (const McapChannel& c : channels_)
      AppendMcapRecord(McapOp::kChannel, McapBody(c), &summary);
  });
  stats_.schema_count = static_cast<std::uint16_t>(schemas_.size());
  stats_.channel_count = static_cast<std::uint32_t>(channels_.size());
  group(McapOp::kStatistics,
        [&] { AppendMcapRecord(McapOp::kStatistics, McapBody(stats_), &summary); });
  group(McapOp::kChunkIndex, [&] {
    for (const McapChunkIndex& c : chunk_indexes_)
      AppendMcapRecord(McapOp::kChunkIndex, McapBody(c), &summary);
  });
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const McapSummaryOffset& g : groups)
    AppendMcapRecord(McapOp::kSummaryOffset, McapBody(g), &summary);
  // The footer's CRC covers the summary and the footer's fields before it.
  McapFooter footer{summary_start, summary_offset_start, 0};
  std::string footer_record;
  AppendMcapRecord(McapOp::kFooter, McapBody(footer), &footer_record);
  footer.summary_crc = McapCrc32(
      std::string_view(footer_record).substr(0, footer_record.size() - 4), McapCrc32(summary));
  footer_record.clear();
  AppendMcapRecord(McapOp::kFooter, McapBody(footer), &footer_record);
  Append(summary);
  Append(footer_record);
  Append(kMcapMagic);
  if (::fsync(fd_) != 0)
    throw InputError(path_ + ": cannot flush the recording to disk: " + std::strerror(errno));
}

}  // namespace mapless::recording
