#include "mapless/io/image_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/lazy_libraries.h"
#include "mapless/io/limits.h"

namespace mapless::io {
namespace {

std::uint32_t Byte(std::string_view b, std::size_t i) { return static_cast<std::uint8_t>(b[i]); }
std::uint32_t Be16(std::string_view b, std::size_t i) { return Byte(b, i) << 8 | Byte(b, i + 1); }
std::uint32_t Le16(std::string_view b, std::size_t i) { return Byte(b, i + 1) << 8 | Byte(b, i); }
std::uint32_t Be32(std::string_view b, std::size_t i) { return Be16(b, i) << 16 | Be16(b, i + 2); }
std::uint32_t Le32(std::string_view b, std::size_t i) { return Le16(b, i + 2) << 16 | Le16(b, i); }

// Sizes are kept in 64 bits until checked: a header may declare anything up to 2^32 - 1.
std::optional<ImageHeader> Make(const char* format, std::int64_t width, std::int64_t height) {
  if (width < 0 || height < 0 || width > (1LL << 31) - 1 || height > (1LL << 31) - 1) {
    return ImageHeader{format, -1, -1};  // absurd: refused by the size check
  }
  return ImageHeader{format, static_cast<int>(width), static_cast<int>(height)};
}

std::optional<ImageHeader> Png(std::string_view b) {
  // Signature, then the IHDR chunk: length, "IHDR", width, height (big-endian).
  if (b.size() < 24 || b.substr(12, 4) != "IHDR") return std::nullopt;
  return Make("PNG", Be32(b, 16), Be32(b, 20));
}

std::optional<ImageHeader> Jpeg(std::string_view b) {
  // Markers from SOI on; the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC) has the size.
  std::size_t i = 2;
  while (i + 4 <= b.size()) {
    if (Byte(b, i) != 0xFF) return std::nullopt;
    const std::uint32_t marker = Byte(b, i + 1);
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      i += 2;
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA) return std::nullopt;  // end, or scan before a frame
    const std::size_t length = Be16(b, i + 2);
    if (length < 2) return std::nullopt;
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (i + 9 > b.size()) return std::nullopt;
      return Make("JPEG", Be16(b, i + 7), Be16(b, i + 5));
    }
    i += 2 + length;
  }
  return std::nullopt;
}

std::optional<ImageHeader> Bmp(std::string_view b) {
  if (b.size() < 26) return std::nullopt;
  const std::uint32_t info_size = Le32(b, 14);
  if (info_size == 12) return Make("BMP", Le16(b, 18), Le16(b, 20));  // BITMAPCOREHEADER
  const auto height = static_cast<std::int32_t>(Le32(b, 22));         // negative: top-down
  const std::int64_t h = height < 0 ? -static_cast<std::int64_t>(height) : height;
  return Make("BMP", static_cast<std::int32_t>(Le32(b, 18)), h);
}

std::optional<ImageHeader> Pnm(std::string_view b) {
  // "P1".."P6", then width and height as decimal text, with whitespace and # comments between.
  std::size_t i = 2;
  std::int64_t values[2] = {0, 0};
  for (std::int64_t& v : values) {
    while (i < b.size()) {
      if (b[i] == '#') {
        while (i < b.size() && b[i] != '\n') ++i;
      } else if (std::isspace(static_cast<unsigned char>(b[i]))) {
        ++i;
      } else {
        break;
      }
    }
    if (i >= b.size() || !std::isdigit(static_cast<unsigned char>(b[i]))) return std::nullopt;
    int digits = 0;
    while (i < b.size() && std::isdigit(static_cast<unsigned char>(b[i]))) {
      if (++digits > 10) return Make("PNM", -1, -1);
      v = v * 10 + (b[i] - '0');
      ++i;
    }
  }
  return Make("PNM", values[0], values[1]);
}

std::optional<ImageHeader> Tiff(std::string_view b) {
  if (b.size() < 8) return std::nullopt;
  const bool le = b[0] == 'I';
  auto u16 = [&](std::size_t i) { return le ? Le16(b, i) : Be16(b, i); };
  auto u32 = [&](std::size_t i) { return le ? Le32(b, i) : Be32(b, i); };
  const std::size_t ifd = u32(4);
  if (ifd + 2 > b.size()) return std::nullopt;
  const std::size_t entries = u16(ifd);
  std::int64_t width = -1;
  std::int64_t height = -1;
  for (std::size_t k = 0; k < entries; ++k) {
    const std::size_t e = ifd + 2 + 12 * k;
    if (e + 12 > b.size()) return std::nullopt;
    const std::uint32_t tag = u16(e);
    if (tag != 256 && tag != 257) continue;
    const std::uint32_t type = u16(e + 2);
    std::int64_t value = -1;
    if (type == 3)
      value = u16(e + 8);  // SHORT
    else if (type == 4)
      value = u32(e + 8);  // LONG
    else
      return std::nullopt;
    (tag == 256 ? width : height) = value;
  }
  if (width < 0 || height < 0) return std::nullopt;
  return Make("TIFF", width, height);
}

}  // namespace

std::optional<ImageHeader> ReadImageHeader(std::string_view b) {
  if (b.size() >= 8 && b.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8)) return Png(b);
  if (b.size() >= 3 && Byte(b, 0) == 0xFF && Byte(b, 1) == 0xD8 && Byte(b, 2) == 0xFF)
    return Jpeg(b);
  if (b.size() >= 2 && b[0] == 'B' && b[1] == 'M') return Bmp(b);
  if (b.size() >= 3 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6' &&
      std::isspace(static_cast<unsigned char>(b[2])))
    return Pnm(b);
  if (b.size() >= 4 && (b.substr(0, 4) == std::string_view("II*\0", 4) ||
                        b.substr(0, 4) == std::string_view("MM\0*", 4)))
    return Tiff(b);
  return std::nullopt;
}

void CheckFrameSize(int width, int height, const std::string& name) {
  if (width < kMinImageSide || height < kMinImageSide) {
    throw InputError(name + ": image is " + std::to_string(width) + "x" + std::to_string(height) +
                     "; mapless needs at least " + std::to_string(kMinImageSide) + "x" +
                     std::to_string(kMinImageSide) + " pixels");
  }
  if (width > kMaxImageSide || height > kMaxImageSide ||
      static_cast<std::int64_t>(width) * height > kMaxImagePixels) {
    throw InputError(name + ": image is " + std::to_string(width) + "x" + std::to_string(height) +
                     "; the limit is " + std::to_string(kMaxImagePixels / 1'000'000) +
                     " megapixels and " + std::to_string(kMaxImageSide) + " pixels a side");
  }
}

namespace {

// Points the process's standard error (the descriptor and std::cerr's buffer) at /dev/null while
// it lives; one at a time.
class QuietStderr {
 public:
  QuietStderr() : lock_(Mutex()) {
    std::fflush(stderr);
    std::cerr.flush();
    saved_ = ::dup(STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    std::fflush(stderr);
    std::cerr.flush();
    if (saved_ >= 0) {
      ::dup2(saved_, STDERR_FILENO);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  static std::mutex& Mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  int saved_ = -1;
};

// A PNG cut short (a write killed half-way) or with a broken chunk structure; checked before the
// decoder, which would print libpng's own message. Walks the chunks to IEND.
bool PngChunksWhole(std::string_view b) {
  std::size_t i = 8;
  while (i + 12 <= b.size()) {
    const std::size_t length = Be32(b, i);
    if (length > b.size() - i - 12) return false;
    if (b.substr(i + 4, 4) == "IEND") return true;
    i += 12 + length;
  }
  return false;
}

// A JPEG ends with EOI (FF D9); a cut one would be decoded half grey, with a warning.
bool JpegEnds(std::string_view b) {
  const std::size_t from = b.size() > 64 ? b.size() - 64 : 0;
  for (std::size_t i = b.size(); i >= from + 2; --i) {
    if (Byte(b, i - 2) == 0xFF && Byte(b, i - 1) == 0xD9) return true;
  }
  return false;
}

}  // namespace

cv::Mat DecodeImage(std::string_view bytes, const std::string& name, int flags, int min_side) {
  const std::optional<ImageHeader> header = ReadImageHeader(bytes);
  if (!header) {
    throw InputError(name +
                     ": not an image mapless reads (PNG, JPEG, BMP, PGM/PPM or TIFF), "
                     "or its header is cut short");
  }
  const std::string what = name + " (" + header->format + ")";
  if (header->width < 0 || header->height < 0) {
    throw InputError(what + ": the header declares an impossible image size");
  }
  if (header->width < min_side || header->height < min_side) {
    throw InputError(what + ": image is " + std::to_string(header->width) + "x" +
                     std::to_string(header->height) + "; at least " + std::to_string(min_side) +
                     "x" + std::to_string(min_side) + " pixels are needed here");
  }
  if (header->width > kMaxImageSide || header->height > kMaxImageSide ||
      static_cast<std::int64_t>(header->width) * header->height > kMaxImagePixels) {
    throw InputError(what + ": the header declares " + std::to_string(header->width) + "x" +
                     std::to_string(header->height) + " pixels; the limit is " +
                     std::to_string(kMaxImagePixels / 1'000'000) + " megapixels and " +
                     std::to_string(kMaxImageSide) + " pixels a side");
  }
  if ((header->format == "PNG" && !PngChunksWhole(bytes)) ||
      (header->format == "JPEG" && !JpegEnds(bytes))) {
    throw InputError(what + ": corrupt image (cut short, or its structure is broken)");
  }
  cv::Mat image;
  {
    // The decoders print their own diagnostics to stderr (OpenCV's imdecode on std::cerr, libpng
    // and libjpeg with fprintf): a corrupt file must come out as one mapless error line, so the
    // standard error stream is pointed at /dev/null for the decoder's call. Decoding is serialised
    // for this; another thread's write to stderr during a decode would be lost (mapless decodes
    // files on the thread that reads them, and logs nothing meanwhile).
    const QuietStderr quiet;
    try {
      // imdecode does not write to its input.
      const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                           const_cast<char*>(bytes.data()));
      image = lazy::ImDecode(buffer, flags);
    } catch (const cv::Exception&) {
      image.release();
    }
  }
  if (image.empty()) throw InputError(what + ": corrupt image (it does not decode)");
  // JPEG's EXIF orientation may turn the image by 90 degrees while decoding.
  const bool as_declared = image.cols == header->width && image.rows == header->height;
  const bool turned = image.cols == header->height && image.rows == header->width;
  if (!as_declared && !turned) {
    throw InputError(what + ": corrupt image (decoded " + std::to_string(image.cols) + "x" +
                     std::to_string(image.rows) + ", the header says " +
                     std::to_string(header->width) + "x" + std::to_string(header->height) + ")");
  }
  return image;
}

cv::Mat ReadImage(const std::string& path, int flags, int min_side) {
  return DecodeImage(ReadFile(path, kMaxImageFileBytes), path, flags, min_side);
}

cv::Size ParseFrameSize(const std::string& text, const std::string& what, cv::Size min) {
  int w = 0, h = 0;
  char x = 0, rest = 0;
  const bool parsed = std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) == 3 && x == 'x';
  if (!parsed || w < min.width || h < min.height || w > 4096 || h > 4096) {
    throw InputError(what + " '" + text + "': expected WIDTHxHEIGHT, " + std::to_string(min.width) +
                     "x" + std::to_string(min.height) + " to 4096x4096");
  }
  return {w, h};
}

void RequireSameSize(const cv::Mat& image, const std::string& path, const cv::Mat& reference,
                     const std::string& reference_path) {
  if (image.size() == reference.size()) return;
  throw InputError(path + ": size " + std::to_string(image.cols) + "x" +
                   std::to_string(image.rows) + " differs from " + reference_path + " (" +
                   std::to_string(reference.cols) + "x" + std::to_string(reference.rows) + ")");
}

}  // namespace mapless::io
