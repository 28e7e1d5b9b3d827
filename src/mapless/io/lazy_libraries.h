// OpenCV's image codecs and camera capture, loaded when first used (dlopen) instead of at every
// process start; FFmpeg the same way (io/lazy_ffmpeg.h).
//
// Linked the usual way, libopencv_imgcodecs, libopencv_videoio and FFmpeg bring about 250 shared
// libraries (GDAL, GStreamer, codecs, ...) whose symbols the dynamic loader binds at every start
// of `mapless` or of a test binary: 0.3 s of CPU each time, whether or not the process ever
// touches an image file (docs/architecture.md, "Shared libraries loaded on first use"). Each
// library is opened at the path the build found it (compiled in), then by its soname; one that
// cannot be opened or lacks a function throws std::runtime_error naming it and what needed it.
// The functions are OpenCV's own (cv::imdecode, cv::imencode, cv::VideoCapture), so images
// decode and encode exactly as when linked.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

namespace mapless::io::lazy {

// cv::imdecode(bytes, flags).
cv::Mat ImDecode(const cv::Mat& bytes, int flags);

// cv::imencode(ext, image, *out, params).
bool ImEncode(const std::string& ext, const cv::Mat& image, std::vector<uchar>* out,
              const std::vector<int>& params);

// A cv::VideoCapture whose functions are those of libopencv_videoio, loaded on construction.
class VideoCapture {
 public:
  VideoCapture();
  ~VideoCapture();
  VideoCapture(const VideoCapture&) = delete;
  VideoCapture& operator=(const VideoCapture&) = delete;

  bool Open(int device, int api);
  bool Open(const std::string& name, int api);
  bool IsOpened() const;
  bool Read(cv::Mat* image);
  double Get(int property) const;

 private:
  cv::VideoCapture* capture() { return reinterpret_cast<cv::VideoCapture*>(storage_); }
  const cv::VideoCapture* capture() const {
    return reinterpret_cast<const cv::VideoCapture*>(storage_);
  }
  alignas(cv::VideoCapture) unsigned char storage_[sizeof(cv::VideoCapture)];
};

// Opens a shared library (at `path`, else by `soname`) for good; throws std::runtime_error
// naming it and `needed_for` when neither opens.
void* OpenLibrary(const char* path, const char* soname, const char* needed_for);

// The address of `symbol` in `library` (opened as `soname`); throws when it is missing.
void* Symbol(void* library, const char* symbol, const char* soname);

}  // namespace mapless::io::lazy
