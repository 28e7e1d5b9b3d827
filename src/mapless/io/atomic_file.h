// Crash-safe file writes: write to a temporary file beside the target, flush it to disk, then
// rename over the target. A reader sees either the old file or the complete new one, never half.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace mapless::io {

// What an output path is: nothing yet or a regular file (written atomically, replaced), or a
// stream such as a device or a pipe (/dev/stdout, /dev/null: written to directly, never replaced).
// Throws InputError naming the path when it is a directory.
enum class OutputKind { kNewOrRegular, kStream };
OutputKind KindOfOutput(const std::string& path);

// Writes `bytes` to `path` atomically (a stream is written to directly); throws InputError naming
// the path on failure. `sync` false: the file is renamed into place before it is on disk; call
// SyncFile() before anything that refers to it is written (many files, one wait: a follower
// catching up on a route).
void WriteFileAtomic(const std::string& path, std::string_view bytes, bool sync = true);
// Writes a file that nothing refers to yet in place (created or truncated; no temporary file and
// rename): a route's new keyframe or image before the manifest lists it. Flush it with
// SyncFiles() before writing what refers to it; a crash before that leaves a file no one reads.
void WriteNewFile(const std::string& path, std::string_view bytes);
// Flushes a written file to disk; throws InputError naming the path on failure.
void SyncFile(const std::string& path);
// Flushes written files to disk: one by one when they are few, else the whole file system they
// are on at once (syncfs: one journal commit instead of one per file).
void SyncFiles(const std::vector<std::string>& paths);

// An image encoded as `ext` (".png", ".jpg", ...) with cv::imencode's `params`
// (cv::IMWRITE_*); throws InputError naming `name` when it cannot be.
std::string EncodeImage(const cv::Mat& image, const std::string& ext, const std::string& name,
                        const std::vector<int>& params = {});

// Encodes an image by the extension of `path` (.png, .jpg, ...) and writes it atomically.
void WriteImageAtomic(const std::string& path, const cv::Mat& image);

// Opens `path` for reading (O_CLOEXEC, never waiting on a FIFO) and checks it is a regular file;
// returns the descriptor (the caller closes it) and its size. Throws InputError naming the path.
int OpenRegularFile(const std::string& path, std::uint64_t* size);

// Reads a whole regular file of at most `max_bytes`; throws InputError naming the path when it
// cannot be read, is not a regular file (a directory, a device such as /dev/zero, a FIFO) or is
// larger than `max_bytes` (io/limits.h has the limit of each kind of file).
std::string ReadFile(const std::string& path, std::size_t max_bytes);

// Creates a directory and its parents; throws InputError naming the path on failure.
void MakeDirectories(const std::string& path);

}  // namespace mapless::io
