#include "mapless/run/report.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/io/atomic_file.h"
#include "mapless/report/pictures.h"
#include "mapless/run/traces.h"
#include "mapless/sim/scenario.h"
#include "mapless/viz/topdown.h"

namespace mapless::run {
namespace {

// Colours of the runs of a suite entry, each its own (the reference is red).
std::string RunColour(std::size_t i) {
  static const char* const kColours[] = {"#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
                                         "#e377c2", "#17becf", "#bcbd22", "#7f7f7f", "#393b79"};
  return kColours[i % (sizeof(kColours) / sizeof(kColours[0]))];
}

// What counts as a success in a suite's table (the defaults of eval/*.h).
std::string SuccessMeans(const std::string& suite) {
  if (suite == "potential")
    return "A run succeeds when the robot reaches the destination (and home, where the entry "
           "homes) without a collision, within " +
           Fixed(eval::PotentialRunOptions{}.success_radius_m, 1) + " m.";
  if (suite == "eigenspace")
    return "A run succeeds when the follower arrives without a collision, within " +
           Fixed(eval::EigenspaceRunOptions{}.arrive_tolerance_m, 1) + " m of the route's end.";
  return "A run succeeds when the robot completes the route without a collision and ends within " +
         Fixed(eval::RepeatRunOptions{}.success_radius_m, 1) + " m of the taught end.";
}

// What the map from above shows, from what is in it.
std::string TopDownCaption(const RunSection& section) {
  std::string text = "From above, in metres (x to the right, y up): the world";
  std::vector<std::string> labels;
  for (const report::PathSpec& p : section.paths)
    if (!p.label.empty()) labels.push_back(p.label);
  if (!labels.empty()) {
    text += " and the paths (";
    for (std::size_t k = 0; k < labels.size(); ++k) text += (k > 0 ? ", " : "") + labels[k];
    text += ")";
  }
  if (section.paths.size() > 1) {
    text += "; the first path, wide and underneath, is the one the others are measured against";
  }
  if (!section.paths.empty())
    text += "; a circle marks where a path starts, a bar its last heading";
  if (!section.markers.empty()) text += "; a star is a destination";
  return text + ".";
}

}  // namespace

std::string Fixed(double value, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, value);
  return buf;
}

report::Series ErrorAlongPath(const std::vector<Pose2>& reference, const std::vector<Pose2>& path,
                              const std::string& color, const std::string& label) {
  report::Series s;
  s.color = color;
  s.label = label;
  double driven = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) driven += std::hypot(path[i].x_m - path[i - 1].x_m, path[i].y_m - path[i - 1].y_m);
    s.x.push_back(driven);
    s.y.push_back(reference.size() >= 2
                      ? eval::SignedDistanceToPath(reference, path[i].x_m, path[i].y_m)
                      : std::nan(""));
  }
  return s;
}

namespace {
std::string g_version = "?";
std::string g_command_line;
}  // namespace

void SetInvocation(const std::string& version, int argc, const char* const* argv) {
  g_version = version;
  g_command_line.clear();
  for (int i = 0; i < argc; ++i) {
    std::string arg = i == 0 ? "mapless" : argv[i];
    const bool plain = !arg.empty() && arg.find_first_not_of(
                                           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                           "0123456789-_./:=,+@%") == std::string::npos;
    if (!plain) {
      std::string quoted = "'";
      for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
      arg = quoted + "'";
    }
    g_command_line += (i > 0 ? " " : "") + arg;
  }
}

std::string ReportByline() {
  char when[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  if (gmtime_r(&now, &utc) != nullptr)
    std::strftime(when, sizeof(when), "%Y-%m-%d %H:%M UTC", &utc);
  return "mapless " + g_version + ", " + when + ": " +
         (g_command_line.empty() ? std::string("(command line not recorded)") : g_command_line);
}

void AddRunSection(report::HtmlReport* html, const RunSection& section) {
  html->Heading(section.title, 2, section.slug);
  if (!section.summary.empty()) html->Paragraph(section.summary);
  html->Figure(report::TopDownSvg(section.world, section.paths, section.markers),
               TopDownCaption(section));
  for (const report::PlotSpec& plot : section.plots) html->Figure(report::LinePlotSvg(plot), "");
  if (!section.pictures.empty()) html->Images(section.pictures, section.pictures_caption);
}

void CheckReportDir(const std::string& dir, const std::string& option) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status) && !fs::is_directory(status))
    throw InputError(option + " " + dir +
                     ": is not a directory (a report is a directory: index.html and PNG plots)");
  const fs::path index = fs::path(dir) / "index.html";
  if (fs::exists(index, ec)) {
    std::ifstream in(index);
    std::string head(4096, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    const bool ours =
        head.find("<meta name=\"generator\" content=\"mapless\">") != std::string::npos ||
        head.find("<title>mapless ") != std::string::npos;
    if (!ours)
      throw InputError(option + " " + dir + ": " + index.string() +
                       " exists and is not a mapless report; choose another directory");
  }
  io::MakeDirectories(dir);
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(option + " " + dir + ": not writable");
}

std::string WriteReport(const std::string& dir, const report::HtmlReport& html,
                        const std::vector<RunSection>& sections) {
  io::MakeDirectories(dir);
  const std::filesystem::path out(dir);
  for (const RunSection& s : sections) {
    std::vector<viz::TopDownPath> paths;
    for (const report::PathSpec& p : s.paths)
      paths.push_back({p.poses, report::CssToBgr(p.color), p.label});
    io::WriteImageAtomic((out / (s.slug + "_topdown.png")).string(),
                         viz::DrawTopDown(s.world, paths, s.markers));
    for (std::size_t k = 0; k < s.plots.size(); ++k)
      io::WriteImageAtomic((out / (s.slug + "_plot" + std::to_string(k + 1) + ".png")).string(),
                           report::LinePlotPicture(s.plots[k]));
  }
  const std::string index = (out / "index.html").string();
  io::WriteFileAtomic(index, html.Html());
  return index;
}

void WriteSuiteReport(const std::string& dir, const std::string& suite, int runs,
                      std::uint64_t seed, const std::vector<const eval::EntryResult*>& entries,
                      const std::vector<std::string>& experiments,
                      const std::vector<const RunTrace*>& traces) {
  report::HtmlReport html("mapless eval " + suite);
  html.Byline(ReportByline());
  html.Paragraph("Runs per line: " + std::to_string(runs) +
                 "; first seed: " + std::to_string(seed) +
                 ". Each run has its own seed (motion and image noise, start perturbation). " +
                 SuccessMeans(suite));
  html.Heading("Results");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const eval::EntryResult& r = *entries[k];
    rows.push_back({r.scenario, experiments[k].empty() ? r.controller : experiments[k],
                    std::to_string(r.successes) + "/" + std::to_string(r.runs),
                    std::to_string(r.collisions), Fixed(r.final_error_m_rms, 3),
                    Fixed(r.final_error_m_std, 3), Fixed(r.lateral_rms_m, 3)});
  }
  html.Table({"scenario", "controller / experiment", "successes", "collisions",
              "final error RMS (m)", "final error std (m)", "lateral RMS (m)"},
             rows);
  std::vector<RunSection> sections;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const eval::EntryResult& r = *entries[k];
    if (r.paths.empty()) continue;
    const sim::Scenario scenario = sim::LoadScenario(r.scenario);
    RunSection s;
    const std::string what = experiments[k].empty() ? r.controller : experiments[k];
    s.title = scenario.name + ": " + what;
    // A file name: the scenario's name (r.scenario may be a path) and the experiment, without
    // anything a file name should not hold.
    s.slug = scenario.name + "_" + what;
    for (char& c : s.slug)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    s.summary = std::to_string(r.successes) + " of " + std::to_string(r.runs) +
                " runs succeeded; " + std::to_string(r.collisions) + " collisions.";
    for (const std::string& f : r.failures) s.summary += " " + f + ".";
    s.world = sim::ApplyVariant(scenario.world, scenario.repeat_variant);
    s.markers = scenario.destinations;
    if (!r.reference_path.empty()) s.paths.push_back({r.reference_path, "#d62728", "reference"});
    report::PlotSpec errors{"Error along the path",
                            "distance driven (m)",
                            "to the reference (m, left +)",
                            {},
                            640,
                            240};
    for (std::size_t i = 0; i < r.paths.size(); ++i) {
      const std::string colour = RunColour(i);
      const std::string label = "run " + std::to_string(i + 1);
      s.paths.push_back({r.paths[i], colour, label, 1.2});
      if (!r.reference_path.empty())
        errors.series.push_back(ErrorAlongPath(r.reference_path, r.paths[i], colour, label));
    }
    if (!errors.series.empty()) s.plots.push_back(errors);
    if (k < traces.size() && traces[k]) {
      s.summary +=
          " Over time, and the pictures: the first run (seed " + std::to_string(seed) + ").";
      traces[k]->AddTo(&s);
    }
    AddRunSection(&html, s);
    sections.push_back(std::move(s));
  }
  WriteReport(dir, html, sections);
}

}  // namespace mapless::run
