#include "mapless/recording/compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <memory>

#include "mapless/core/check.h"

namespace mapless::recording {

void CheckCompression(const std::string& compression) {
  if (compression != "" && compression != "zstd" && compression != "lz4")
    throw InputError("compression '" + compression + "': must be none, zstd or lz4");
}

std::string Compress(const std::string& compression, std::string_view data) {
  CheckCompression(compression);
  if (compression.empty()) return std::string(data);
  std::string out;
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(data.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3);
    MAPLESS_CHECK(!ZSTD_isError(n), "zstd: " << ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.contentSize = data.size();
  out.resize(LZ4F_compressFrameBound(data.size(), &prefs));
  const std::size_t n =
      LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), &prefs);
  MAPLESS_CHECK(!LZ4F_isError(n), "lz4: " << LZ4F_getErrorName(n));
  out.resize(n);
  return out;
}

std::string Decompress(const std::string& compression, std::string_view data,
                       std::uint64_t uncompressed_size, const std::string& what) {
  if (compression.empty()) {
    MAPLESS_CHECK(data.size() == uncompressed_size, what << ": uncompressed_size "
                                                         << uncompressed_size << " but "
                                                         << data.size() << " bytes of records");
    return std::string(data);
  }
  MAPLESS_CHECK(
      compression == "zstd" || compression == "lz4",
      what << ": compression '" << compression << "' is not one mapless reads (zstd, lz4)");
  MAPLESS_CHECK(uncompressed_size <= kMaxUncompressedChunkBytes,
                what << ": uncompressed_size " << uncompressed_size << " is above "
                     << kMaxUncompressedChunkBytes << " bytes");
  std::string out(static_cast<std::size_t>(uncompressed_size), '\0');
  if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    MAPLESS_CHECK(!ZSTD_isError(n), what << ": zstd: " << ZSTD_getErrorName(n));
    MAPLESS_CHECK(n == out.size(),
                  what << ": zstd gave " << n << " bytes, uncompressed_size says " << out.size());
    return out;
  }
  LZ4F_dctx* raw = nullptr;
  MAPLESS_CHECK(!LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)),
                what << ": lz4: no decompression context");
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(
      raw, &LZ4F_freeDecompressionContext);
  std::size_t in_pos = 0, out_pos = 0;
  while (true) {
    std::size_t in_n = data.size() - in_pos, out_n = out.size() - out_pos;
    const std::size_t hint = LZ4F_decompress(ctx.get(), out.data() + out_pos, &out_n,
                                             data.data() + in_pos, &in_n, nullptr);
    MAPLESS_CHECK(!LZ4F_isError(hint), what << ": lz4: " << LZ4F_getErrorName(hint));
    in_pos += in_n;
    out_pos += out_n;
    if (hint == 0) break;  // the frame is complete
    MAPLESS_CHECK(in_pos < data.size() && (out_n > 0 || in_n > 0),
                  what << ": lz4: the frame is cut short or longer than uncompressed_size");
  }
  MAPLESS_CHECK(out_pos == out.size(), what << ": lz4 gave " << out_pos
                                            << " bytes, uncompressed_size says " << out.size());
  return out;
}

}  // namespace mapless::recording
