// Reading a scenario's world from YAML (used by scenario.cc; docs/simulator.md describes the
// fields): the textures, the objects (rooms, multi-point walls and `repeat` expanded), the world,
// and its `sessions:` block. Errors name the file, line and field (io::YamlMap::Fail).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mapless/core/pose.h"
#include "mapless/io/yaml_reader.h"
#include "mapless/sim/world.h"

namespace mapless::sim::yaml {

using io::YamlMap;

// A seed derived from two (SplitMix64's finaliser): default texture seeds from the world seed.
std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b);
Eigen::Vector2d Vec2(const YamlMap& m, const std::string& key);
// [x, y, theta_deg] as a pose (theta in radians, wrapped).
Pose2 PoseDeg(const YamlMap& m, const std::string& key);
void RequirePositive(const YamlMap& m, const std::string& key, double v);

TextureSpec ParseTexture(const YamlMap& m, std::uint64_t default_seed, const std::string& base_dir);
// Appends the objects of one entry of world.objects (or of a variant's `add`).
void ParseObject(const YamlMap& m, std::uint64_t seed, const std::string& base_dir,
                 std::vector<WorldObject>* out);
World ParseWorld(const YamlMap& m, std::uint64_t seed, const std::string& base_dir);
// A scenario's `sessions:` block; every tag that comes and goes must be an object's in `world`.
WorldChange ParseWorldChange(const YamlMap& m, const World& world);

}  // namespace mapless::sim::yaml
