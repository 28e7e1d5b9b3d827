#include "mapless/robot/camera_image.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"

namespace mapless::robot {

namespace {

struct Layout {
  int channels;
  int bytes_per_channel;
  int grey_code;  // cv::COLOR_* to grey, -1: already grey
};

bool LayoutOf(const std::string& e, Layout* out) {
  if (e == "mono8" || e == "8UC1")
    *out = {1, 1, -1};
  else if (e == "mono16" || e == "16UC1")
    *out = {1, 2, -1};
  else if (e == "rgb8")
    *out = {3, 1, cv::COLOR_RGB2GRAY};
  else if (e == "bgr8" || e == "8UC3")
    *out = {3, 1, cv::COLOR_BGR2GRAY};
  else if (e == "rgba8")
    *out = {4, 1, cv::COLOR_RGBA2GRAY};
  else if (e == "bgra8" || e == "8UC4")
    *out = {4, 1, cv::COLOR_BGRA2GRAY};
  else
    return false;
  return true;
}

}  // namespace

bool IsSupportedEncoding(const std::string& encoding) {
  Layout l{};
  return LayoutOf(encoding, &l);
}

cv::Mat GreyFromRaw(const std::string& encoding, std::uint32_t width, std::uint32_t height,
                    std::uint32_t step, bool big_endian, std::string_view data) {
  Layout l{};
  MAPLESS_CHECK(LayoutOf(encoding, &l),
                "image encoding '" << encoding.substr(0, 32)
                                   << "' is not supported (mono8, mono16, rgb8, bgr8, rgba8, "
                                      "bgra8; or send a CompressedImage)");
  MAPLESS_CHECK(width >= 16 && height >= 16 &&
                    width <= static_cast<std::uint32_t>(io::kMaxImageSide) &&
                    height <= static_cast<std::uint32_t>(io::kMaxImageSide) &&
                    static_cast<std::int64_t>(width) * height <= io::kMaxImagePixels,
                "image " << width << "x" << height << ": must be 16x16 to " << io::kMaxImageSide
                         << " a side and at most " << io::kMaxImagePixels << " pixels");
  const std::uint64_t row = static_cast<std::uint64_t>(width) * l.channels * l.bytes_per_channel;
  MAPLESS_CHECK(step >= row, "image step " << step << " is less than a row (" << row << " bytes)");
  MAPLESS_CHECK(static_cast<std::uint64_t>(step) * height <= data.size(),
                "image data " << data.size() << " bytes; step x height needs "
                              << static_cast<std::uint64_t>(step) * height);
  const int type = CV_MAKETYPE(l.bytes_per_channel == 1 ? CV_8U : CV_16U, l.channels);
  const cv::Mat view(static_cast<int>(height), static_cast<int>(width), type,
                     const_cast<char*>(data.data()), step);
  cv::Mat grey;
  if (l.bytes_per_channel == 2) {
    cv::Mat swapped = view.clone();
    const bool host_big = false;  // x86_64 and ARM robots are little-endian
    if (big_endian != host_big) {
      for (int y = 0; y < swapped.rows; ++y) {
        auto* p = swapped.ptr<std::uint16_t>(y);
        for (int x = 0; x < swapped.cols; ++x)
          p[x] = static_cast<std::uint16_t>((p[x] >> 8) | (p[x] << 8));
      }
    }
    swapped.convertTo(grey, CV_8U, 1.0 / 256.0);
  } else if (l.grey_code < 0) {
    grey = view.clone();
  } else {
    cv::cvtColor(view, grey, l.grey_code);
  }
  return grey;
}

cv::Mat GreyFromCompressed(const std::string& format, std::string_view data) {
  MAPLESS_CHECK(
      format.find("jpeg") != std::string::npos || format.find("jpg") != std::string::npos ||
          format.find("png") != std::string::npos || format.empty(),
      "compressed image format '" << format.substr(0, 48) << "' is not supported (jpeg, png)");
  MAPLESS_CHECK(data.size() <= io::kMaxImageFileBytes,
                "compressed image of " << data.size() << " bytes is over the limit");
  return io::DecodeImage(data, "compressed image", cv::IMREAD_GRAYSCALE, 16);
}

cv::Mat PrepareFrame(const cv::Mat& grey, CameraMount mount, cv::Size size) {
  cv::Mat upright;
  switch (mount) {
    case CameraMount::kUpright:
      upright = grey;
      break;
    case CameraMount::kRotated180:
      cv::flip(grey, upright, -1);
      break;
    case CameraMount::kMirrored:
      cv::flip(grey, upright, 1);
      break;
    case CameraMount::kFlippedVertically:
      cv::flip(grey, upright, 0);
      break;
  }
  if (size.area() == 0 || upright.size() == size) return upright;
  cv::Mat out;
  const bool shrink = size.width < upright.cols;
  cv::resize(upright, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

}  // namespace mapless::robot
