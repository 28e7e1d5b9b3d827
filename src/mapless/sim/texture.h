// Procedural textures for the simulated world, generated from a seed: multi-scale noise, bricks,
// tiles, random blobs and rectangles, posters, a low-texture plain variant, or an image file.
// Each texture is a power-of-two grayscale image that tiles, with a mip pyramid so that the
// renderer samples it without aliasing at any distance.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <tuple>
#include <vector>

namespace mapless::sim {

enum class TextureType { kNoise, kBricks, kTiles, kBlobs, kPoster, kPlain, kChecker, kImage };

// Parses "noise", "bricks", ... ; throws InputError on an unknown name.
TextureType ParseTextureType(const std::string& name);
const char* TextureTypeName(TextureType type);

struct TextureSpec {
  TextureType type = TextureType::kNoise;
  std::uint64_t seed = 1;
  double texel_m = 0.01;  // world size of one texel, metres (ignored when `fit` is set)
  bool fit = false;       // stretch one copy over the whole surface (posters, pictures)
  double mean = 128.0;    // mean intensity, 0..255
  double contrast = 1.0;  // 1 = the type's normal contrast; 0.15 gives a low-texture surface
  int size_px = 1024;     // side of the texture image, a power of two (64..2048); 1024 keeps
                          // exact repeats (which fool feature matching) metres apart
  std::string file;       // image file for kImage (grayscale; resized to size_px)
  // The share of the surface (0..1) that has changed since it was taught (a world that changes
  // between sessions, sim/sessions.h): patches of a second texture of the same kind (another
  // seed) cover that share, growing from the same places as it rises (leaves, wet ground, snow).
  double changed = 0.0;

  void Validate() const;  // throws InputError naming the field and value
};

// What makes two texture specs the same texture (the renderer generates each distinct one once):
// type, seed, texel_m, fit, mean, contrast, size_px, file, changed.
using TextureKey =
    std::tuple<int, std::uint64_t, double, bool, double, double, int, std::string, double>;
TextureKey TextureKeyOf(const TextureSpec& spec);

// A tileable texture with its mip pyramid: levels[0] is size_px x size_px, each next level half.
struct Texture {
  // Raw view of one level for the renderer's inner loop: a continuous square of side 2^log2_size.
  struct LevelView {
    const std::uint8_t* data = nullptr;
    int log2_size = 0;
  };
  std::vector<cv::Mat> levels;   // CV_8UC1, power-of-two sides
  std::vector<LevelView> views;  // one per level, pointing into `levels`
  double texel_m = 0.01;
  bool fit = false;
};

// Generates the texture for `spec` (deterministic for a given spec).
std::shared_ptr<const Texture> GenerateTexture(const TextureSpec& spec);

// Only the base image, without mip levels (for tests and previews).
cv::Mat GenerateTextureImage(const TextureSpec& spec);

// The image of a texture of which a share `spec.changed` has changed (GenerateTextureImage calls
// it when that share is above 0): the texture with `changed` 0, covered in patches by another
// texture of the same type.
cv::Mat ChangedTexture(const TextureSpec& spec);

}  // namespace mapless::sim
