// A ROS 1 bag (format 2.0) checked before rosbag_storage opens it. The library trusts every
// length in the file: a record header's length is allocated as read (a 19 KB file asked for
// 2.3 GB), and the records inside a chunk are read at the index's offsets without a bounds check.
// So the whole structure it will touch is walked here first, from the file's own bytes:
//   - every top-level record (header length, header fields, data length) lies inside the file
//     and the records follow each other to its end;
//   - the bag header's index position, connection and chunk counts lead to that many connection
//     and chunk-info records, each chunk-info points at a chunk record, and each chunk is followed
//     by one index record per connection it holds;
//   - every chunk (none, bz2, lz4) decompresses to exactly its declared size (at most
//     kMaxBagChunkBytes), its records follow each other to its end, and every index offset is the
//     start of a record that leads to a message of a known connection.
// Any breach throws InputError naming the file, the byte offset and what was wrong. The cost is
// one extra read (and decompression) of the bag when it is opened.
#pragma once

#include <cstdint>
#include <string>

namespace mapless::recording {

// A chunk may not decompress to more than this (rosbag writes 768 KiB chunks by default).
constexpr std::uint32_t kMaxBagChunkBytes = 256u << 20;

// Throws InputError unless `path` is a bag (format 2.0) that rosbag_storage can read safely.
void CheckBagStructure(const std::string& path);

}  // namespace mapless::recording
