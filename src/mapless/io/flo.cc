#include "mapless/io/flo.h"

#include <cstdint>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"

namespace mapless::io {
namespace {

constexpr float kFloMagic = 202021.25f;

bool EndsWith(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

cv::Mat ReadFlo(const std::string& path) {
  return ParseFlo(ReadFile(path, 12 + 8 * static_cast<std::size_t>(kMaxImagePixels)), path);
}

cv::Mat ParseFlo(const std::string& bytes, const std::string& path) {
  if (bytes.size() < 12) throw InputError(path + ": not a .flo file (shorter than its header)");
  float magic = 0.f;
  std::int32_t width = 0;
  std::int32_t height = 0;
  std::memcpy(&magic, bytes.data(), 4);
  std::memcpy(&width, bytes.data() + 4, 4);
  std::memcpy(&height, bytes.data() + 8, 4);
  if (magic != kFloMagic)
    throw InputError(path + ": not a .flo file (magic number is not 202021.25)");
  if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide ||
      static_cast<std::int64_t>(width) * height > kMaxImagePixels) {
    throw InputError(path + ": .flo size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is not valid (at most " + std::to_string(kMaxImagePixels / 1'000'000) +
                     " megapixels, " + std::to_string(kMaxImageSide) + " a side)");
  }
  const std::size_t need =
      12 + static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 8;
  if (bytes.size() < need) {
    throw InputError(path + ": truncated .flo file (" + std::to_string(bytes.size()) + " bytes, " +
                     std::to_string(need) + " expected for " + std::to_string(width) + "x" +
                     std::to_string(height) + ")");
  }
  cv::Mat flow(height, width, CV_32FC2);
  for (int y = 0; y < height; ++y) {
    std::memcpy(flow.ptr(y), bytes.data() + 12 + static_cast<std::size_t>(y) * width * 8,
                static_cast<std::size_t>(width) * 8);
  }
  return flow;
}

void WriteFlo(const std::string& path, const cv::Mat& flow) {
  MAPLESS_CHECK(flow.type() == CV_32FC2 && !flow.empty(), "WriteFlo: expected a CV_32FC2 field");
  std::string bytes(12 + flow.total() * 8, '\0');
  const std::int32_t width = flow.cols;
  const std::int32_t height = flow.rows;
  std::memcpy(bytes.data(), &kFloMagic, 4);
  std::memcpy(bytes.data() + 4, &width, 4);
  std::memcpy(bytes.data() + 8, &height, 4);
  for (int y = 0; y < flow.rows; ++y) {
    std::memcpy(bytes.data() + 12 + static_cast<std::size_t>(y) * width * 8, flow.ptr(y),
                static_cast<std::size_t>(width) * 8);
  }
  WriteFileAtomic(path, bytes);
}

cv::Mat ReadKittiFlow(const std::string& path, cv::Mat* valid) {
  const cv::Mat png = ReadImage(path, cv::IMREAD_UNCHANGED);
  if (png.type() != CV_16UC3)
    throw InputError(path + ": not a KITTI flow PNG (expected 16-bit, 3 channels)");
  cv::Mat flow(png.size(), CV_32FC2);
  cv::Mat mask(png.size(), CV_8UC1);
  for (int y = 0; y < png.rows; ++y) {
    const auto* p = png.ptr<cv::Vec3w>(y);  // OpenCV loads B, G, R
    auto* f = flow.ptr<cv::Vec2f>(y);
    uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < png.cols; ++x) {
      const bool ok = p[x][0] > 0;
      m[x] = ok ? 255 : 0;
      f[x] = ok ? cv::Vec2f((p[x][2] - 32768.f) / 64.f, (p[x][1] - 32768.f) / 64.f)
                : cv::Vec2f(1e10f, 1e10f);
    }
  }
  if (valid != nullptr) *valid = mask;
  return flow;
}

cv::Mat ReadFlowFile(const std::string& path, cv::Mat* valid) {
  if (EndsWith(path, ".png")) return ReadKittiFlow(path, valid);
  cv::Mat flow = ReadFlo(path);
  if (valid != nullptr) valid->release();
  return flow;
}

}  // namespace mapless::io
