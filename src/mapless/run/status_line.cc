#include "mapless/run/status_line.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "mapless/run/report.h"

namespace mapless::run {
namespace {

double Number(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : 0.0;
}

// Where the method is on its route and what it sees, from its own status fields.
std::string Progress(const nlohmann::json& s) {
  std::string out;
  if (s.contains("destination")) {
    out += " | keyframe " + std::to_string(static_cast<long>(Number(s, "destination")));
  }
  if (s.contains("matches")) {
    out += " | " + std::to_string(static_cast<long>(Number(s, "matches"))) + " matches";
  }
  if (s.contains("index")) {
    out += " | image " + std::to_string(static_cast<long>(Number(s, "index"))) + " (p " +
           Fixed(Number(s, "probability"), 2) + ")";
  }
  if (s.contains("leg")) out += " | leg " + s["leg"].dump();
  if (s.contains("plane_fraction")) {
    out += " | ground " + Fixed(100.0 * Number(s, "plane_fraction"), 0) + "%";
  }
  if (s.contains("speed_fraction")) {
    out += " | speed " + Fixed(100.0 * Number(s, "speed_fraction"), 0) + "%";
  }
  return out;
}

}  // namespace

std::string StatusLineText(const nlohmann::json& s, double driven_m, double elapsed_s,
                           std::size_t width) {
  const std::string method = s.value("method", std::string("run"));
  std::string state = s.value("state", std::string("?"));
  const std::string status = s.value("status", std::string());
  if (!status.empty() && status != state) state += " (" + status + ")";
  std::string line = method + ": " + state + Progress(s) + " | " + Fixed(Number(s, "v_mps"), 2) +
                     " m/s " + Fixed(Number(s, "omega_radps"), 2) + " rad/s | " +
                     Fixed(driven_m, 1) + " m | " + Fixed(elapsed_s, 1) + " s";
  const auto reason = s.find("reason");
  if (reason != s.end() && reason->is_string() && s.value("state", "") != "driving") {
    line += " | " + reason->get<std::string>();
  }
  if (line.size() > width) line = line.substr(0, width - 3) + "...";
  return line;
}

StatusLine::StatusLine(bool wanted) : enabled_(wanted && ::isatty(STDERR_FILENO) == 1) {}
StatusLine::~StatusLine() { Clear(); }

void StatusLine::Show(const nlohmann::json& status) {
  const double t = Number(status, "t_s");
  if (last_t_s_ >= 0.0 && t > last_t_s_ && t - last_t_s_ < 5.0) {
    driven_m_ += std::abs(Number(status, "v_mps")) * (t - last_t_s_);
  }
  last_t_s_ = t;
  if (first_t_s_ < 0.0) first_t_s_ = t;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (shown_ && now - last_print_ < std::chrono::milliseconds(200)) return;
  last_print_ = now;
  // \r and "erase to the end of the line": a shorter line leaves nothing of the longer one.
  std::fprintf(stderr, "\r%s\033[K", StatusLineText(status, driven_m_, t - first_t_s_).c_str());
  std::fflush(stderr);
  shown_ = true;
}

void StatusLine::Clear() {
  if (!shown_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  shown_ = false;
}

}  // namespace mapless::run
