// Seeded random generator with its own uniform and normal samplers, so that results never depend
// on the standard library's distributions (which differ between implementations).
// Engine: xoshiro256** (Blackman & Vigna), seeded through SplitMix64.
#pragma once

#include <cstdint>

namespace mapless {

class Rng {
 public:
  explicit Rng(std::uint64_t seed);

  // Raw 64 random bits.
  std::uint64_t NextU64();
  // Uniform in [0, 1).
  double Uniform();
  // Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [0, n); n > 0.
  std::uint64_t UniformInt(std::uint64_t n);
  // Standard normal N(0, 1) by the Marsaglia polar method.
  double Normal();
  double Normal(double mean, double stddev) { return mean + stddev * Normal(); }

  // A new generator whose stream is a deterministic function of this seed and `stream`; does not
  // advance this generator (for per-frame or per-object sub-streams).
  static Rng Derive(std::uint64_t seed, std::uint64_t stream);

 private:
  std::uint64_t s_[4];
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace mapless
