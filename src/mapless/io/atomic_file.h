// Crash-safe file writes: write to a temporary file beside the target, flush it to disk, then
// rename over the target. A reader sees either the old file or the complete new one, never half.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

namespace mapless::io {

// Writes `bytes` to `path` atomically; throws InputError naming the path on failure.
void WriteFileAtomic(const std::string& path, std::string_view bytes);

// Encodes an image by the extension of `path` (.png, .jpg, ...) and writes it atomically.
void WriteImageAtomic(const std::string& path, const cv::Mat& image);

// Reads a whole file; throws InputError naming the path if it cannot be read.
std::string ReadFile(const std::string& path);

// Creates a directory and its parents; throws InputError naming the path on failure.
void MakeDirectories(const std::string& path);

}  // namespace mapless::io
