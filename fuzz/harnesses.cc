#include "harnesses.h"

#include "mapless/core/check.h"
#include "mapless/io/flo.h"
#include "mapless/io/tum.h"
#include "mapless/navigation/potential.h"
#include "mapless/route/route_store.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::fuzz {
namespace {

template <typename F>
void AcceptInputError(F&& parse) {
  try {
    parse();
  } catch (const InputError&) {
    // Bad input, reported as it should be.
  }
}

}  // namespace

void RouteManifest(const std::string& input) {
  AcceptInputError([&] { route::ParseManifest(input, "fuzz/manifest.json"); });
}

void RouteKeyframe(const std::string& input) {
  AcceptInputError([&] { route::ParseKeyframe(input, "fuzz/000000.yml"); });
}

void Scenario(const std::string& input) {
  // World files named by the scenario resolve against a directory that does not exist.
  AcceptInputError([&] { sim::ParseScenario(input, "fuzz.yaml", "/nonexistent-mapless-fuzz"); });
}

void Config(const std::string& input) {
  AcceptInputError([&] { sim::ParseDriveOptions(input, "fuzz.yaml"); });
}

void Calibration(const std::string& input) {
  AcceptInputError([&] { navigation::CalibrationFromYaml(input, "fuzz.yaml"); });
}

void Flo(const std::string& input) {
  AcceptInputError([&] { io::ParseFlo(input, "fuzz.flo"); });
}

void Tum(const std::string& input) {
  AcceptInputError([&] { io::ParseTum(input, "fuzz.txt"); });
}

const std::vector<NamedHarness>& Harnesses() {
  static const std::vector<NamedHarness> harnesses = {{"route_manifest", RouteManifest},
                                                      {"route_keyframe", RouteKeyframe},
                                                      {"scenario", Scenario},
                                                      {"config", Config},
                                                      {"calibration", Calibration},
                                                      {"flo", Flo},
                                                      {"tum", Tum}};
  return harnesses;
}

}  // namespace mapless::fuzz
