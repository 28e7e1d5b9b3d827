// Reading images from files and bytes with the limits of io/limits.h. The image size is read from
// the file's header before anything is decoded, so that a small file declaring 30000x30000 pixels
// is refused instead of allocating gigabytes. Formats: PNG, JPEG, BMP, PNM (PBM/PGM/PPM) and TIFF;
// anything else is refused (OpenCV would pick a decoder by content, whatever the extension).
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace mapless::io {

struct ImageHeader {
  std::string format;  // "PNG", "JPEG", "BMP", "PNM", "TIFF"
  int width = 0;
  int height = 0;
};

// The format and size declared by an image's header; nullopt when the bytes are not one of the
// formats above or the header is cut short.
std::optional<ImageHeader> ReadImageHeader(std::string_view bytes);

// Decodes image bytes (cv::IMREAD_* `flags`); the decoders' own messages are silenced (standard
// error points at /dev/null during the call, one decode at a time). Throws InputError naming
// `name` when the format is not supported, the declared size is over kMaxImagePixels /
// kMaxImageSide or below `min_side` on either side, or the bytes do not decode.
cv::Mat DecodeImage(std::string_view bytes, const std::string& name, int flags, int min_side = 1);

// Reads and decodes an image file (at most kMaxImageFileBytes); errors as DecodeImage.
cv::Mat ReadImage(const std::string& path, int flags, int min_side = 1);

// Throws InputError naming `name` unless `width` x `height` is within the frame limits
// (kMinImageSide .. kMaxImageSide, at most kMaxImagePixels).
void CheckFrameSize(int width, int height, const std::string& name);

// Throws InputError naming both files unless `image` has the size of `reference`.
void RequireSameSize(const cv::Mat& image, const std::string& path, const cv::Mat& reference,
                     const std::string& reference_path);

// A frame size written WxH ("320x240"), from `min` up to 4096 a side; throws InputError naming
// `what` (an option: "--size") and the text otherwise.
cv::Size ParseFrameSize(const std::string& text, const std::string& what, cv::Size min);

}  // namespace mapless::io
