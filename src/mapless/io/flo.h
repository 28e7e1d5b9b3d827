// Optical-flow files: Middlebury .flo (read and write) and KITTI 16-bit PNG flow (read).
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace mapless::io {

// Middlebury .flo: float32 magic 202021.25, int32 width, int32 height, then (u, v) float32 per
// pixel, row-major, little-endian. Unknown flow is stored as values > 1e9.
// Reads a CV_32FC2 field; throws InputError naming the file when it is missing, truncated or not a
// .flo file.
cv::Mat ReadFlo(const std::string& path);
// The same on the file's bytes (`name` stands for the file in errors; fuzz/fuzz_flo.cc).
cv::Mat ParseFlo(const std::string& bytes, const std::string& name);
// Writes a CV_32FC2 field atomically.
void WriteFlo(const std::string& path, const cv::Mat& flow);

// KITTI flow PNG: u = (R - 2^15) / 64, v = (G - 2^15) / 64, valid where B > 0. Returns the field
// (invalid pixels set to 1e10, like Middlebury's unknown) and fills `valid` (CV_8UC1, 255 = valid).
cv::Mat ReadKittiFlow(const std::string& path, cv::Mat* valid);

// Either format, by extension (.flo or .png).
cv::Mat ReadFlowFile(const std::string& path, cv::Mat* valid);

}  // namespace mapless::io
