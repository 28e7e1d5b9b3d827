// A world that changes between sessions (issue 45): a route is taught on session 0 and repeated
// on sessions 1, 2, ..., each a little further from the one it was taught on, as a place drifts
// from summer to winter or from noon to dusk:
//   - the light: the camera's brightness and contrast drift, with a swing from session to session
//     (clouds, the hour), and the light turns (which faces of walls and boxes are lit);
//   - the textures: a growing share of every surface is covered by patches of another texture of
//     its kind (fallen leaves, wet ground, snow), growing from the same places session by session;
//   - objects that come and go: each object with a listed tag is there on a session or not, by a
//     seeded draw (parked cars).
// Pure and deterministic: the same scenario and session give the same world.
#pragma once

#include <string>
#include <vector>

#include "mapless/sim/scenario.h"

namespace mapless::sim {

// Session s's scenario: the taught world with s sessions of `scenario.sessions`' change applied
// (session 0 is the world the route is taught in). The repeat's variant removes the objects that
// are away on that session. Throws InputError when the scenario has no `sessions` block or s < 0.
Scenario SessionScenario(const Scenario& scenario, int session);

// What session s changes, for logs and reports: "light -6 grey levels, contrast 0.94, light from
// 102 deg, 18% of textures changed, cars away: car2, car5".
std::string DescribeSession(const Scenario& scenario, int session);

}  // namespace mapless::sim
