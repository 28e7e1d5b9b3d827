// Generated worlds (`mapless sim generate`): a scenario file drawn from a seed, so that the methods
// are judged on worlds nobody tuned them on. Each world has a taught path made of straight runs,
// S-curves, hairpins, turns and turns in place; a layout of one kind (a room with clutter, a
// corridor that follows the path, open ground with trees and buildings, a car park); floors and
// walls from rich to texture-poor; light that differs between the teach and the repeat; and, in a
// stated share of worlds, an object put on the path after the teach. What was drawn is written
// into the scenario's `labels:`, with `feasible: false` and the reason for a world no method can
// be expected to handle (no texture at all): such worlds are labelled, not left out.
//
// The output is an ordinary scenario (scenario.h): every command loads it. The same options give
// the same text, byte for byte.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mapless::sim {

struct GenerateOptions {
  std::uint64_t seed = 1;
  std::string kind;  // indoor, corridor, outdoor, car_park; "": drawn from the seed
  // The share of worlds (drawn per seed) with an object put on the taught path after the teach
  // (label obstacle_on_path), and the share without any texture (labelled infeasible).
  double obstacle_share = 0.25;
  double textureless_share = 0.04;
  void Validate() const;  // throws InputError naming the field
};

// The kinds of world, in the order `--kind` lists them.
std::vector<std::string> GeneratorKinds();

// The scenario's YAML text (name gen_KIND_SEED).
std::string GenerateScenarioYaml(const GenerateOptions& options);

}  // namespace mapless::sim
