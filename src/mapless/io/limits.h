// Limits on everything mapless reads from outside: files, images, frames. A reader that meets more
// than its limit refuses the input with an InputError naming the file, before it allocates for it.
// docs/hardening.md lists every limit and why it is where it is.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mapless::io {

// Hand-written YAML: scenarios, worlds, run configurations, calibrations. The largest built-in
// scenario is 3 KB; yaml-cpp needs about 100 bytes of memory per byte of dense YAML.
inline constexpr std::size_t kMaxYamlFileBytes = std::size_t{1} << 20;  // 1 MiB
// The values of a YAML document with every alias expanded (docs/hardening.md): a 1 MiB document
// without aliases has at most half a million ("[1,1,1,...]"), so only aliases within aliases reach
// it; walking a million takes about 0.1 s.
inline constexpr std::uint64_t kMaxYamlExpandedNodes = std::uint64_t{1} << 20;
// A route's manifest.json (about 120 bytes per keyframe).
inline constexpr std::size_t kMaxManifestBytes = std::size_t{16} << 20;  // 16 MiB
// One keyframe file (keypoints and descriptors as YAML; an ORB-500 keyframe is about 150 KB).
inline constexpr std::size_t kMaxKeyframeFileBytes = std::size_t{4} << 20;  // 4 MiB
// Keypoints of one keyframe.
inline constexpr int kMaxKeypoints = 20'000;
// Keyframes of one route (a 10 km route with a keyframe every 0.5 m).
inline constexpr int kMaxKeyframes = 20'000;
// TUM trajectories (about 60 bytes a pose).
inline constexpr std::size_t kMaxTrajectoryBytes = std::size_t{64} << 20;  // 64 MiB
// An encoded image file.
inline constexpr std::size_t kMaxImageFileBytes = std::size_t{256} << 20;  // 256 MiB
// A decoded image or frame: 40 megapixels (8K video is 33), at most 16384 on a side.
inline constexpr std::int64_t kMaxImagePixels = 40'000'000;
inline constexpr int kMaxImageSide = 16384;
// The smallest frame the methods work on (the simulator's smallest camera; OpenCV's flow needs 12).
inline constexpr int kMinImageSide = 16;

}  // namespace mapless::io
