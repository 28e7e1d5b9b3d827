// Writing MCAP files (mcap_format.h) as ROS 2 tools write them: schemas and channels in the data
// section before the messages that use them, messages in chunks (none, zstd or lz4) each followed
// by its message indexes, and on Close() the summary (schemas, channels, statistics, chunk
// indexes), summary offsets, the footer and the closing magic, so readers can seek.
//
// A recording killed before Close() keeps every chunk already written (McapReader reads it up to
// the cut): a chunk is written when it holds `chunk_bytes` or spans `chunk_ns` of log time, so a
// kill loses at most that much. The file is written in place (not renamed at the end: a rename
// would lose everything on a kill), and refused if it exists.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mapless/recording/mcap_format.h"

namespace mapless::recording {

struct McapWriterOptions {
  std::string compression = "zstd";  // "", "zstd" or "lz4"
  std::size_t chunk_bytes = 1 << 20;
  std::uint64_t chunk_ns = 1'000'000'000;
  std::string profile = "ros2";
  std::string library = "mapless";
};

class McapWriter {
 public:
  // Creates `path` (InputError when it exists or cannot be created).
  McapWriter(const std::string& path, const McapWriterOptions& options);
  ~McapWriter();  // closes the file if Close() was not called (errors are swallowed there)
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids from 1, in order.
  std::uint16_t AddSchema(const std::string& name, const std::string& encoding,
                          const std::string& data);
  std::uint16_t AddChannel(std::uint16_t schema_id, const std::string& topic,
                           const std::string& message_encoding, const StringMap& metadata = {});
  // Sequence numbers count per channel from 0.
  void Write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
             std::string_view data);
  void Flush();  // writes the open chunk now
  void Close();  // the summary, footer and magic; then the file is synced to disk

  std::uint64_t messages() const { return stats_.message_count; }

 private:
  void Append(std::string_view bytes);
  void WriteChunk();

  std::string path_;
  McapWriterOptions options_;
  int fd_ = -1;
  std::uint64_t offset_ = 0;  // bytes written so far
  std::uint32_t data_crc_ = 0;
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
  // The open chunk.
  std::string chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  std::map<std::uint16_t, McapMessageIndex> chunk_index_;
  std::vector<McapChunkIndex> chunk_indexes_;
  McapStatistics stats_;
  bool closed_ = false;
};

}  // namespace mapless::recording
