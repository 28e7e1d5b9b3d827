// Recorded and live camera inputs: a video file, a folder of images (in file-name order), or a
// camera device. Every source yields grey frames with timestamps.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::io {

struct Frame {
  cv::Mat image;                  // CV_8UC1
  Timestamp t_ns = 0;             // from the video's frame times, or index / fps for folders
  std::string name;               // file name (folders) or frame number
  std::optional<Pose2> odometry;  // the wheel odometry at the frame (recordings that have it)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame; false at the end. Throws InputError on an unreadable frame (naming it).
  virtual bool Next(Frame* frame) = 0;
  virtual std::string Describe() const = 0;
};

// Frame rates accepted for image folders (timestamps are index / fps).
inline constexpr double kMinFolderFps = 0.01;
inline constexpr double kMaxFolderFps = 1000.0;

// True for "camera:N" and "/dev/videoN": a live camera, not a recording.
bool IsLiveCamera(const std::string& spec);

// The image files of a folder (.png .jpg .jpeg .bmp .pgm .ppm .tif .tiff, any case), as paths in
// file-name order; other files are not listed. Throws InputError naming the folder when it cannot
// be read or holds no image file.
std::vector<std::string> ImageFilesIn(const std::string& dir);

// Opens `spec`: "camera:N" or "/dev/videoN" for a camera, a directory for an image folder
// (.png .jpg .jpeg .bmp .pgm .ppm .tif .tiff), anything else as a video file. `folder_fps` gives
// the timestamps of folder frames. Throws InputError naming the source when it cannot be opened.
// Every frame is checked against the limits of io/limits.h (size, pixels; folder images are read
// with their header checked first) and must have the size of the first one.
std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec, double folder_fps = 10.0);

}  // namespace mapless::io
