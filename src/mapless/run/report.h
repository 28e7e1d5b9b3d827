// The HTML report of `mapless demo` and `mapless eval SUITE --report DIR` (issue 20): what was
// run, the results table, per run or scenario a top-down view with the reference and every
// driven path, plots (error along the path, commands over time, the belief), pictures of chosen
// frames; DIR/index.html (self-contained) and PNG twins of the main plots (DIR/*.png).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mapless/eval/suite.h"
#include "mapless/report/html.h"
#include "mapless/report/svg.h"
#include "mapless/sim/world.h"

namespace mapless::run {

class RunTrace;  // traces.h

// One run (or one suite entry) as the report shows it.
struct RunSection {
  std::string title;  // e.g. "Teach & repeat: sloped funnel lane"
  std::string slug;   // file names of its PNGs: SLUG_topdown.png, SLUG_plot1.png, ...
  std::string summary;
  sim::World world;
  std::vector<Eigen::Vector2d> markers;
  std::vector<report::PathSpec> paths;  // the first is the reference
  std::vector<report::PlotSpec> plots;
  std::vector<std::pair<cv::Mat, std::string>> pictures;  // chosen frames
  std::string pictures_caption;
};

// Checks, before any work, that a report can go to `dir` without losing anything: it must be a
// new or empty directory or one holding a report mapless wrote (its index.html says so), and
// writable; throws InputError naming `option` and `dir` otherwise. Creates the directory.
void CheckReportDir(const std::string& dir, const std::string& option);

// The reference path's signed distance (m, left positive) of each pose of `path`, against the
// distance driven along it (m): the "error along the path" plot's series.
// A number with `digits` decimals, for the report's text and tables.
std::string Fixed(double value, int digits);

report::Series ErrorAlongPath(const std::vector<Pose2>& reference, const std::vector<Pose2>& path,
                              const std::string& color, const std::string& label);

void AddRunSection(report::HtmlReport* html, const RunSection& section);

// The mapless version and command line of this process (main() sets them once), for the line
// under a report's title: "mapless 0.1.0, 2026-11-27 17:40 UTC: mapless demo --out x".
void SetInvocation(const std::string& version, int argc, const char* const* argv);
std::string ReportByline();

// Writes DIR/index.html and every section's PNG twins (DIR/SLUG_topdown.png, DIR/SLUG_plotN.png),
// each atomically; returns the path of index.html.
std::string WriteReport(const std::string& dir, const report::HtmlReport& html,
                        const std::vector<RunSection>& sections);

// `mapless eval SUITE --report DIR`: the results table and, for each entry with paths, a section:
// the scenario's world, the reference path and every run, the error along the path, and what
// `traces[k]` (the first run of entry k, frame by frame; may be null) adds: commands over time,
// the method's own plots, chosen frames.
void WriteSuiteReport(const std::string& dir, const std::string& suite, int runs,
                      std::uint64_t seed, const std::vector<const eval::EntryResult*>& entries,
                      const std::vector<std::string>& experiments,
                      const std::vector<const RunTrace*>& traces);

}  // namespace mapless::run
