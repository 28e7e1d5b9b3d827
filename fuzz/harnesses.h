// Fuzz harnesses: one per parser of outside input. Each feeds the bytes to the parser and accepts
// a result or a mapless::InputError (the one way bad input may fail); anything else (a crash, a
// sanitizer report, another exception, a hang) is a bug. The same functions run under libFuzzer
// (fuzz_main.cc, scripts/fuzz.sh) and, on the kept inputs, in the ordinary test suite
// (fuzz_regression_test.cc).
#pragma once

#include <string>
#include <vector>

namespace mapless::fuzz {

using Harness = void (*)(const std::string& input);

struct NamedHarness {
  const char* name;  // the fuzz target is fuzz_<name>; kept inputs live in fuzz/corpus/<name>/
  Harness run;
};

void RouteManifest(const std::string& input);  // route/manifest.json (nlohmann-json)
void RouteKeyframe(const std::string& input);  // route/keyframes/NNNNNN.yml (OpenCV FileStorage)
void Scenario(const std::string& input);       // scenario / world YAML
void Config(const std::string& input);         // run configuration YAML (--config)
void Calibration(const std::string& input);    // planar-flow calibration YAML (navigate)
void Flo(const std::string& input);            // Middlebury .flo
void Tum(const std::string& input);            // TUM trajectory text

const std::vector<NamedHarness>& Harnesses();

}  // namespace mapless::fuzz
