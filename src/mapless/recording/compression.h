// Chunk compression as MCAP names it: "" (none), "zstd" (libzstd) and "lz4" (the LZ4 frame
// format, liblz4). Decompression trusts nothing: the declared size is bounded and must be met.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace mapless::recording {

// The largest chunk mapless will decompress (MCAP writers use chunks of about 1-4 MB).
inline constexpr std::uint64_t kMaxUncompressedChunkBytes = 512ull << 20;

// Throws InputError for an unknown name.
void CheckCompression(const std::string& compression);
std::string Compress(const std::string& compression, std::string_view data);
// `what` names the chunk in errors.
std::string Decompress(const std::string& compression, std::string_view data,
                       std::uint64_t uncompressed_size, const std::string& what);

}  // namespace mapless::recording
