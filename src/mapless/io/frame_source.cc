#include "mapless/io/frame_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>  // the IMREAD_ flags (the library itself is loaded lazily)
#include <opencv2/imgproc.hpp>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/image_file.h"
#include "mapless/io/lazy_libraries.h"
#include "mapless/io/limits.h"
#include "mapless/io/video_file.h"

namespace mapless::io {
namespace {

cv::Mat ToGrey(const cv::Mat& in) {
  if (in.channels() == 1) return in;
  cv::Mat grey;
  cv::cvtColor(in, grey, in.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

class FolderSource : public FrameSource {
 public:
  FolderSource(const std::string& dir, double fps)
      : dir_(dir), fps_(fps), files_(ImageFilesIn(dir)) {}
  bool Next(Frame* frame) override {
    if (next_ >= files_.size()) return false;
    const std::string& path = files_[next_];
    const cv::Mat img = ReadImage(path, cv::IMREAD_GRAYSCALE, kMinImageSide);
    if (!size_.empty() && img.size() != size_) {
      throw InputError(path + ": image is " + std::to_string(img.cols) + "x" +
                       std::to_string(img.rows) + " but the folder's first image is " +
                       std::to_string(size_.width) + "x" + std::to_string(size_.height));
    }
    size_ = img.size();
    frame->image = img;
    frame->t_ns = FromSeconds(static_cast<double>(next_) / fps_);
    frame->name = std::filesystem::path(path).filename().string();
    ++next_;
    return true;
  }
  std::string Describe() const override {
    return dir_ + " (" + std::to_string(files_.size()) + " images)";
  }

 private:
  std::string dir_;
  double fps_;
  std::vector<std::string> files_;
  std::size_t next_ = 0;
  cv::Size size_;
};

// A camera (camera:N, /dev/videoN) through OpenCV's V4L2 back end. Video files are decoded with
// FFmpeg directly (io/video_file.h).
class CameraSource : public FrameSource {
 public:
  CameraSource(const std::string& spec, bool by_number, int device) : spec_(spec) {
    bool ok = false;
    try {
      ok = by_number ? capture_.Open(device, cv::CAP_V4L2) : capture_.Open(spec, cv::CAP_V4L2);
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok || !capture_.IsOpened()) throw InputError(spec + ": cannot open camera");
    fps_ = capture_.Get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0.0 && fps_ < 1000.0)) fps_ = 30.0;
    // The container's declared size, checked before the first frame is decoded.
    const double width = capture_.Get(cv::CAP_PROP_FRAME_WIDTH);
    const double height = capture_.Get(cv::CAP_PROP_FRAME_HEIGHT);
    if (width > 0.0 && height > 0.0 && width < 1e9 && height < 1e9) {
      CheckFrameSize(static_cast<int>(width), static_cast<int>(height), spec);
    }
  }
  bool Next(Frame* frame) override {
    cv::Mat img;
    try {
      if (!capture_.Read(&img) || img.empty()) return false;
    } catch (const cv::Exception&) {
      throw InputError(spec_ + ": frame " + std::to_string(index_) + " does not decode");
    }
    const std::string name = spec_ + " frame " + std::to_string(index_);
    CheckFrameSize(img.cols, img.rows, name);
    if (!size_.empty() && img.size() != size_) {
      throw InputError(name + ": image is " + std::to_string(img.cols) + "x" +
                       std::to_string(img.rows) + " but the first frame is " +
                       std::to_string(size_.width) + "x" + std::to_string(size_.height));
    }
    size_ = img.size();
    if (img.depth() != CV_8U) {
      throw InputError(name + ": frames must have 8-bit channels");
    }
    frame->image = ToGrey(img);
    frame->t_ns = FromSeconds(static_cast<double>(index_) / fps_);
    frame->name = std::to_string(index_);
    ++index_;
    return true;
  }
  std::string Describe() const override { return spec_; }

 private:
  std::string spec_;
  lazy::VideoCapture capture_;
  double fps_ = 30.0;
  long index_ = 0;
  cv::Size size_;
};

}  // namespace

std::vector<std::string> ImageFilesIn(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (!it->is_regular_file(type_ec)) continue;
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm" ||
        ext == ".ppm" || ext == ".tif" || ext == ".tiff") {
      files.push_back(it->path().string());
    }
  }
  if (ec) throw InputError(dir + ": " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir + ": no image files in this folder");
  return files;
}

bool IsLiveCamera(const std::string& spec) {
  return spec.rfind("camera:", 0) == 0 || spec.rfind("/dev/video", 0) == 0;
}

std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec, double folder_fps) {
  MAPLESS_CHECK(folder_fps >= kMinFolderFps && folder_fps <= kMaxFolderFps,
                "--fps " << folder_fps << ": must be in [" << kMinFolderFps << ", " << kMaxFolderFps
                         << "] frames per second");
  if (spec.rfind("camera:", 0) == 0) {
    int device = 0;
    const std::string number = spec.substr(7);
    std::size_t used = 0;
    try {
      device = std::stoi(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (number.empty() || used != number.size() || device < 0 || device > 63) {
      throw InputError(spec + ": expected camera:N with a device number 0..63");
    }
    return std::make_unique<CameraSource>(spec, true, device);
  }
  if (spec.rfind("/dev/video", 0) == 0) return std::make_unique<CameraSource>(spec, false, 0);
  if (std::filesystem::is_directory(spec)) return std::make_unique<FolderSource>(spec, folder_fps);
  if (!std::filesystem::exists(spec)) throw InputError(spec + ": no such file, folder or camera");
  return OpenVideoFile(spec);
}

}  // namespace mapless::io
