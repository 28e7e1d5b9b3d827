#include "mapless/sim/sessions.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"

namespace mapless::sim {
namespace {

constexpr double kDefaultLightAzimuthDeg = 57.5;  // the renderer's fixed light (renderer.cc)

struct Light {
  double bias = 0.0;
  double gain = 1.0;
  double azimuth_deg = kDefaultLightAzimuthDeg;
};

Light LightOf(const Scenario& scenario, const WorldChange& change, int session) {
  Light light;
  const double s = session;
  const double swing =
      session == 0
          ? 0.0
          : Rng::Derive(scenario.seed, 0x5E5510000ULL + static_cast<std::uint64_t>(session))
                .Uniform(-1.0, 1.0);
  light.bias = scenario.camera.effects.bias + change.brightness * s + change.light_swing * swing;
  light.bias = std::clamp(light.bias, -255.0, 255.0);
  light.gain = scenario.camera.effects.gain * std::max(0.1, 1.0 + change.contrast * s);
  light.azimuth_deg = scenario.world.light_azimuth_deg.value_or(kDefaultLightAzimuthDeg) +
                      change.light_turn_deg * s;
  return light;
}

// The tags of the objects away on a session (none on session 0: the taught world).
std::vector<std::string> AwayOn(const Scenario& scenario, const WorldChange& change, int session) {
  std::vector<std::string> away;
  if (session == 0) return away;
  for (std::size_t i = 0; i < change.come_and_go.size(); ++i) {
    const std::uint64_t stream = 0xC0AE000000ULL + static_cast<std::uint64_t>(session) * 4096 +
                                 static_cast<std::uint64_t>(i);
    if (Rng::Derive(scenario.seed, stream).Uniform() >= change.presence)
      away.push_back(change.come_and_go[i]);
  }
  return away;
}

void Change(TextureSpec* texture, double share) { texture->changed = share; }

}  // namespace

Scenario SessionScenario(const Scenario& scenario, int session) {
  MAPLESS_CHECK(scenario.sessions,
                "scenario '" << scenario.name << "' has no sessions: block (a world that changes)");
  MAPLESS_CHECK(session >= 0, "session " << session << "; must be >= 0");
  const WorldChange& change = *scenario.sessions;
  Scenario out = scenario;
  out.name = scenario.name + " session " + std::to_string(session);
  const Light light = LightOf(scenario, change, session);
  out.camera.effects.bias = light.bias;
  out.camera.effects.gain = light.gain;
  out.world.light_azimuth_deg = light.azimuth_deg;
  const double share = std::min(1.0, change.texture * session);
  Change(&out.world.ground, share);
  if (out.world.ceiling) Change(&*out.world.ceiling, share);
  for (WorldObject& o : out.world.objects) Change(&o.texture, share);
  for (const std::string& tag : AwayOn(scenario, change, session)) {
    auto& remove = out.repeat_variant.remove;
    if (std::find(remove.begin(), remove.end(), tag) == remove.end()) remove.push_back(tag);
  }
  return out;
}

std::string DescribeSession(const Scenario& scenario, int session) {
  MAPLESS_CHECK(scenario.sessions, "scenario '" << scenario.name << "' has no sessions: block");
  const WorldChange& change = *scenario.sessions;
  const Light light = LightOf(scenario, change, session);
  std::ostringstream out;
  out.precision(3);
  out << "session " << session << ": light " << light.bias << " grey levels, contrast "
      << light.gain << ", light from " << std::fmod(light.azimuth_deg, 360.0) << " deg, "
      << std::lround(100.0 * std::min(1.0, change.texture * session)) << "% of textures changed";
  const auto away = AwayOn(scenario, change, session);
  if (!away.empty()) {
    out << ", away:";
    for (const std::string& tag : away) out << ' ' << tag;
  }
  return out.str();
}

}  // namespace mapless::sim
