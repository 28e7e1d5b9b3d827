// Video files decoded with FFmpeg's own API (libavformat, libavcodec, libswscale), as grey frames.
//
// Not through OpenCV's VideoCapture: OpenCV 4.6 wraps its converted frame as the stream's declared
// size while it allocated the buffer at the coded size, and a malformed file whose declared size is
// larger reads past that buffer (a heap overflow found by fuzz/harnesses.cc VideoFile; the input is
// kept as fuzz/corpus/video_file/crash-opencv-ffmpeg-coded-size-overflow). Here every frame is
// converted at the size of the decoded frame itself, into a buffer of that size.
#pragma once

#include <memory>
#include <string>

#include "mapless/io/frame_source.h"

namespace mapless::io {

// Opens a video file; throws InputError naming it when it is not a video FFmpeg can decode, or
// its declared frame size is over the limits of io/limits.h. Frames: grey, the first frame's size
// (a frame of another size is an InputError), timestamps index / the stream's frame rate (30 when
// the file does not say).
std::unique_ptr<FrameSource> OpenVideoFile(const std::string& path);

}  // namespace mapless::io
