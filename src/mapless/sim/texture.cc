#include "mapless/sim/texture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/io/image_file.h"

namespace mapless::sim {
namespace {

struct TypeName {
  TextureType type;
  const char* name;
};
constexpr TypeName kTypeNames[] = {
    {TextureType::kNoise, "noise"},     {TextureType::kBricks, "bricks"},
    {TextureType::kTiles, "tiles"},     {TextureType::kBlobs, "blobs"},
    {TextureType::kPoster, "poster"},   {TextureType::kPlain, "plain"},
    {TextureType::kChecker, "checker"}, {TextureType::kImage, "image"}};

// Tileable value noise: a random lattice of `cells` x `cells` values, bicubic-smoothed by
// upsampling with wrap-around, so that the result tiles.
cv::Mat TileableNoise(int size, int cells, Rng* rng) {
  cv::Mat lattice(cells, cells, CV_32F);
  for (int y = 0; y < cells; ++y) {
    for (int x = 0; x < cells; ++x) lattice.at<float>(y, x) = static_cast<float>(rng->Uniform());
  }
  // Pad by wrapping, upsample, crop: keeps continuity across the tile border.
  const int pad = 2;
  cv::Mat padded;
  cv::copyMakeBorder(lattice, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  const double scale = static_cast<double>(size) / cells;
  cv::Mat up;
  cv::resize(padded, up, cv::Size(), scale, scale, cv::INTER_CUBIC);
  const int off = static_cast<int>(std::lround(pad * scale));
  return up(cv::Rect(off, off, size, size)).clone();
}

// Fractal (multi-octave) noise in [-1, 1] roughly, tileable. `persistence` is the amplitude ratio
// between an octave and the next finer one: higher values keep more fine detail (corners).
cv::Mat FractalNoise(int size, int base_cells, int octaves, Rng* rng, double persistence = 0.6) {
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32F);
  double amplitude = 1.0;
  double total = 0.0;
  int cells = base_cells;
  for (int o = 0; o < octaves && cells <= size; ++o) {
    sum += amplitude * (TileableNoise(size, cells, rng) - 0.5);
    total += amplitude;
    amplitude *= persistence;
    cells *= 2;
  }
  return sum * (2.0 / total);
}

// Draws a filled rectangle that wraps around the tile border: the copies shifted by a whole tile
// that touch the image, each filled once (what cv::rectangle with cv::FILLED fills, clipped).
void WrappedRect(cv::Mat* img, int x, int y, int w, int h, float value) {
  const int size = img->cols;
  const cv::Rect bounds(0, 0, size, img->rows);
  for (int oy = -size; oy <= size; oy += size) {
    for (int ox = -size; ox <= size; ox += size) {
      const cv::Rect r = cv::Rect(x + ox, y + oy, w, h) & bounds;
      if (r.area() > 0) (*img)(r).setTo(cv::Scalar(value));
    }
  }
}

// The same for an anti-aliased filled ellipse: only the copies whose bounding square (the longer
// axis and the anti-aliasing's pixel around it) touches the image are drawn.
void WrappedEllipse(cv::Mat* img, int x, int y, int ax, int ay, double angle, float value) {
  const int size = img->cols;
  const int reach = std::max(ax, ay) + 2;
  for (int oy = -size; oy <= size; oy += size) {
    for (int ox = -size; ox <= size; ox += size) {
      const int cx = x + ox;
      const int cy = y + oy;
      if (cx + reach < 0 || cy + reach < 0 || cx - reach >= size || cy - reach >= img->rows) {
        continue;
      }
      cv::ellipse(*img, cv::Point(cx, cy), cv::Size(ax, ay), angle, 0, 360, cv::Scalar(value),
                  cv::FILLED, cv::LINE_AA);
    }
  }
}

// Small dark and bright specks (pebbles, pores, dirt): strong corners for feature detectors.
void Specks(cv::Mat* img, int count, int max_size, Rng* rng) {
  const int size = img->cols;
  for (int i = 0; i < count; ++i) {
    const int x = static_cast<int>(rng->UniformInt(static_cast<std::uint64_t>(size)));
    const int y = static_cast<int>(rng->UniformInt(static_cast<std::uint64_t>(size)));
    const int w = 1 + static_cast<int>(rng->UniformInt(static_cast<std::uint64_t>(max_size)));
    const int h = 1 + static_cast<int>(rng->UniformInt(static_cast<std::uint64_t>(max_size)));
    WrappedRect(img, x, y, w, h, static_cast<float>(rng->Uniform() < 0.5 ? -1.0 : 1.0));
  }
}

// Signed content in roughly [-1, 1]; scaled to mean/contrast at the end.
// The generators below were designed at 256 texels; larger textures keep every element's size in
// texels (so a texture looks the same at any size_px) and only repeat less often: element counts
// grow with the area and noise lattices with the side.
int Scaled(int count_at_256, int size) {
  return std::max(1, static_cast<int>(std::lround(count_at_256 * size / 256.0)));
}
int ScaledArea(int count_at_256, int size) {
  return std::max(1, static_cast<int>(std::lround(count_at_256 * (size / 256.0) * (size / 256.0))));
}

cv::Mat Noise(int size, Rng* rng) {
  cv::Mat img = FractalNoise(size, Scaled(4, size), 9, rng, 0.75) * 1.5;
  Specks(&img, size * size / 400, 2, rng);
  return img;
}

cv::Mat Bricks(int size, Rng* rng) {
  cv::Mat img = FractalNoise(size, Scaled(16, size), 4, rng, 0.8) * 0.35;
  const int bh = std::min(32, size / 2);  // brick height and width in texels
  const int bw = std::min(64, size);
  const int rows = size / bh;
  const int cols = size / bw;
  const int mortar = 2;
  for (int r = 0; r < rows; ++r) {
    const int shift = (r % 2) * bw / 2;
    for (int c = 0; c < cols; ++c) {
      const float tone = static_cast<float>(rng->Uniform(-0.6, 0.6));
      const int x0 = c * bw + shift;
      for (int y = r * bh; y < (r + 1) * bh; ++y) {
        float* row = img.ptr<float>(y);
        for (int x = 0; x < bw; ++x) {
          float& v = row[(x0 + x) % size];
          const bool is_mortar = y - r * bh < mortar || x < mortar;
          v = is_mortar ? -1.0f : v + tone;
        }
      }
    }
  }
  Specks(&img, size * size / 300, 2, rng);
  return img;
}

cv::Mat Tiles(int size, Rng* rng) {
  cv::Mat img = FractalNoise(size, Scaled(8, size), 5, rng, 0.75) * 0.35;
  const int step = std::min(32, size);  // tile side in texels
  const int n = size / step;
  const int grout = 2;
  for (int ty = 0; ty < n; ++ty) {
    for (int tx = 0; tx < n; ++tx) {
      const float tone = static_cast<float>(rng->Uniform(-0.5, 0.5));
      img(cv::Rect(tx * step, ty * step, step, step)) += tone;
      // A few specks per tile give corners for feature detectors.
      for (int k = 0; k < 5; ++k) {
        const int sx = tx * step + grout + static_cast<int>(rng->UniformInt(step - 3 * grout));
        const int sy = ty * step + grout + static_cast<int>(rng->UniformInt(step - 3 * grout));
        const int w = 2 + static_cast<int>(rng->UniformInt(std::max(1, step / 6)));
        cv::rectangle(img, cv::Rect(sx, sy, w, w), cv::Scalar(rng->Uniform(-1, 1)), cv::FILLED);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    img(cv::Rect(0, i * step, size, grout)).setTo(-1.0);
    img(cv::Rect(i * step, 0, grout, size)).setTo(-1.0);
  }
  return img;
}

cv::Mat Blobs(int size, Rng* rng) {
  cv::Mat img = FractalNoise(size, Scaled(4, size), 9, rng, 0.7) * 0.5;
  const int count = ScaledArea(180 + static_cast<int>(rng->UniformInt(60)), size);
  for (int i = 0; i < count; ++i) {
    const int x = static_cast<int>(rng->UniformInt(size));
    const int y = static_cast<int>(rng->UniformInt(size));
    const float value = static_cast<float>(rng->Uniform(-1.0, 1.0));
    const int extent = 2 + static_cast<int>(rng->UniformInt(12));
    if (rng->Uniform() < 0.5) {
      WrappedRect(&img, x, y, extent, 3 + static_cast<int>(rng->UniformInt(extent + 1)), value);
    } else {
      // Drawn in this order (the angle first) so that every compiler makes the same texture:
      // the order in which a call's arguments are evaluated is unspecified in C++.
      const double angle = rng->Uniform(0, 180);
      const int ay = 2 + static_cast<int>(rng->UniformInt(extent + 1));
      WrappedEllipse(&img, x, y, extent, ay, angle, value);
    }
  }
  return img;
}

cv::Mat Poster(int size, Rng* rng) {
  // High-contrast picture: a background, big shapes, and lines of "text" bars. Not tileable.
  cv::Mat img(size, size, CV_32F, cv::Scalar(rng->Uniform(-0.8, 0.8)));
  img += FractalNoise(size, 4, 4, rng) * 0.2;
  const int shapes = 6 + static_cast<int>(rng->UniformInt(6));
  for (int i = 0; i < shapes; ++i) {
    const int cy = static_cast<int>(rng->UniformInt(size));  // y first, as above: one order
    const cv::Point c(static_cast<int>(rng->UniformInt(size)), cy);
    const int r = size / 16 + static_cast<int>(rng->UniformInt(size / 5));
    const double value = rng->Uniform(-1.0, 1.0);
    if (i % 2 == 0) {
      cv::circle(img, c, r, cv::Scalar(value), cv::FILLED, cv::LINE_AA);
    } else {
      cv::rectangle(img, cv::Rect(c.x - r, c.y - r / 2, 2 * r, r), cv::Scalar(value), cv::FILLED);
    }
  }
  const int lines = 4 + static_cast<int>(rng->UniformInt(5));
  for (int l = 0; l < lines; ++l) {
    const int y = size / 10 + l * (size * 8 / 10) / lines;
    int x = size / 12;
    while (x < size * 11 / 12) {
      const int w = size / 40 + static_cast<int>(rng->UniformInt(size / 12));
      cv::rectangle(img, cv::Rect(x, y, w, std::max(2, size / 40)), cv::Scalar(-1.0), cv::FILLED);
      x += w + size / 60;
    }
  }
  const int border = std::max(2, size / 50);
  cv::rectangle(img, cv::Rect(0, 0, size, size), cv::Scalar(1.0), border);
  return img;
}

cv::Mat Plain(int size, Rng* rng) { return FractalNoise(size, Scaled(2, size), 3, rng) * 0.3; }

cv::Mat Checker(int size) {
  cv::Mat img(size, size, CV_32F);
  const int step = size / 8;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      img.at<float>(y, x) = ((x / step + y / step) % 2 == 0) ? 1.0f : -1.0f;
    }
  }
  return img;
}

bool IsPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

// Where a surface changes first: a smooth field of patches (a few per tile) and the level below
// which a share `changed` of it lies (measured on a 64 x 64 grid). Rising shares cover growing
// patches around the same places.
cv::Mat ChangeWeights(int size, std::uint64_t seed, double changed) {
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + 0xC4A26EDULL);
  const cv::Mat field = FractalNoise(size, Scaled(3, size), 4, &rng, 0.5);
  std::vector<float> grid;
  const int step = std::max(1, size / 64);
  for (int y = 0; y < size; y += step)
    for (int x = 0; x < size; x += step) grid.push_back(field.at<float>(y, x));
  std::sort(grid.begin(), grid.end());
  const auto at = static_cast<std::size_t>(changed * static_cast<double>(grid.size() - 1));
  const float level = changed >= 1.0 ? grid.back() + 1.0f : grid[at];
  // A soft edge a twentieth of the field's range wide: the patches' borders are not a pixel step.
  const float soft = std::max(1e-6f, 0.05f * (grid.back() - grid.front()));
  cv::Mat weights = (level - field) / soft + 0.5;
  return cv::min(cv::max(weights, 0.0), 1.0);
}

}  // namespace

cv::Mat ChangedTexture(const TextureSpec& spec) {
  TextureSpec before = spec;
  before.changed = 0.0;
  TextureSpec after = before;
  after.seed = spec.seed * 0xD1B54A32D192ED03ULL + 0x5E55;
  if (after.type == TextureType::kImage) after.type = TextureType::kNoise;
  cv::Mat a;
  cv::Mat b;
  GenerateTextureImage(before).convertTo(a, CV_32F);
  GenerateTextureImage(after).convertTo(b, CV_32F);
  const cv::Mat w = ChangeWeights(spec.size_px, spec.seed, spec.changed);
  const cv::Mat mixed = a.mul(1.0 - w) + b.mul(w);
  cv::Mat out;
  mixed.convertTo(out, CV_8U);
  return out;
}

TextureType ParseTextureType(const std::string& name) {
  for (const auto& t : kTypeNames) {
    if (name == t.name) return t.type;
  }
  throw InputError("unknown texture type '" + name +
                   "' (known: noise, bricks, tiles, blobs, poster, plain, checker, image)");
}

const char* TextureTypeName(TextureType type) {
  for (const auto& t : kTypeNames) {
    if (type == t.type) return t.name;
  }
  return "?";
}

TextureKey TextureKeyOf(const TextureSpec& spec) {
  return std::make_tuple(static_cast<int>(spec.type), spec.seed, spec.texel_m, spec.fit, spec.mean,
                         spec.contrast, spec.size_px, spec.file, spec.changed);
}

void TextureSpec::Validate() const {
  MAPLESS_CHECK(texel_m >= 1e-5 && texel_m <= 100.0,
                "TextureSpec.texel_m = " << texel_m << "; must be in [1e-5, 100]");
  MAPLESS_CHECK(mean >= 0.0 && mean <= 255.0,
                "TextureSpec.mean = " << mean << "; must be in [0, 255]");
  MAPLESS_CHECK(contrast >= 0.0 && contrast <= 4.0,
                "TextureSpec.contrast = " << contrast << "; must be in [0, 4]");
  MAPLESS_CHECK(IsPowerOfTwo(size_px) && size_px >= 64 && size_px <= 2048,
                "TextureSpec.size_px = " << size_px << "; must be a power of two in [64, 2048]");
  MAPLESS_CHECK(type != TextureType::kImage || !file.empty(),
                "TextureSpec.file is empty; an image texture needs a file");
  MAPLESS_CHECK(changed >= 0.0 && changed <= 1.0,
                "TextureSpec.changed = " << changed << "; must be in [0, 1]");
}

cv::Mat GenerateTextureImage(const TextureSpec& spec) {
  spec.Validate();
  if (spec.changed > 0.0) return ChangedTexture(spec);
  Rng rng(spec.seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(spec.type));
  const int size = spec.size_px;
  if (spec.type == TextureType::kImage) {
    const cv::Mat img = io::ReadImage(spec.file, cv::IMREAD_GRAYSCALE);
    cv::Mat out;
    cv::resize(img, out, cv::Size(size, size), 0, 0, cv::INTER_AREA);
    return out;
  }
  cv::Mat signal;
  switch (spec.type) {
    case TextureType::kNoise:
      signal = Noise(size, &rng);
      break;
    case TextureType::kBricks:
      signal = Bricks(size, &rng);
      break;
    case TextureType::kTiles:
      signal = Tiles(size, &rng);
      break;
    case TextureType::kBlobs:
      signal = Blobs(size, &rng);
      break;
    case TextureType::kPoster:
      signal = Poster(size, &rng);
      break;
    case TextureType::kPlain:
      signal = Plain(size, &rng);
      break;
    case TextureType::kChecker:
      signal = Checker(size);
      break;
    case TextureType::kImage:
      break;
  }
  cv::Mat out;
  signal.convertTo(out, CV_8U, 80.0 * spec.contrast, spec.mean);
  return out;
}

std::shared_ptr<const Texture> GenerateTexture(const TextureSpec& spec) {
  auto texture = std::make_shared<Texture>();
  texture->texel_m = spec.texel_m;
  texture->fit = spec.fit;
  texture->levels.push_back(GenerateTextureImage(spec));
  // Box-filtered mip levels down to 1x1 (exact 2x2 averages keep the texture tileable).
  while (texture->levels.back().cols > 1) {
    cv::Mat next;
    cv::resize(texture->levels.back(), next, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    texture->levels.push_back(next);
  }
  for (const cv::Mat& level : texture->levels) {
    CV_Assert(level.isContinuous());
    int log2 = 0;
    while ((1 << log2) < level.cols) ++log2;
    texture->views.push_back(Texture::LevelView{level.ptr<std::uint8_t>(0), log2});
  }
  return texture;
}

}  // namespace mapless::sim
