#include "mapless/eval/experiences.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"

namespace mapless::eval {

namespace {

constexpr std::size_t kMaxOffsetsBytes = 1 << 20;

double Fraction(int part, int whole) {
  return whole > 0 ? static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

}  // namespace

double PlaceFigures::single_fraction() const { return Fraction(single_within, visits); }
double PlaceFigures::experiences_fraction() const { return Fraction(experiences_within, visits); }

SessionsDataset LoadSessionsDataset(const std::string& dir) {
  const std::string file = dir + "/offsets.txt";
  MAPLESS_CHECK(std::filesystem::is_directory(dir), dir << ": not a directory");
  std::istringstream lines(io::ReadFile(file, kMaxOffsetsBytes));
  SessionsDataset data;
  data.dir = dir;
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream fields(line);
    SessionsDataset::Visit visit;
    int place = 0;
    std::string rest;
    const bool parsed =
        static_cast<bool>(fields >> place >> visit.session >> visit.offset_px) && !(fields >> rest);
    MAPLESS_CHECK(parsed && place >= 0 && place <= 99 && visit.session >= 0 &&
                      visit.session <= 99 && std::isfinite(visit.offset_px) &&
                      std::abs(visit.offset_px) <= 1e5,
                  file << ":" << number << ": expected \"place session dx_px\" (place and "
                       << "session 0-99, a finite offset), got \"" << line << "\"");
    char name[16];
    std::snprintf(name, sizeof(name), "/%02d%02d.png", visit.session, place);
    visit.image = dir + name;
    MAPLESS_CHECK(std::filesystem::is_regular_file(visit.image),
                  file << ":" << number << ": place " << place << ", session " << visit.session
                       << ": no image " << visit.image);
    auto& visits = data.places[place];
    for (const auto& v : visits) {
      MAPLESS_CHECK(v.session != visit.session, file << ":" << number << ": place " << place
                                                     << ", session " << visit.session
                                                     << " listed twice");
    }
    visits.push_back(visit);
  }
  MAPLESS_CHECK(!data.places.empty(), file << ": no place listed");
  for (auto& [place, visits] : data.places) {
    MAPLESS_CHECK(visits.size() >= 2,
                  file << ": place " << place << " has one session; at least two are needed");
    std::sort(visits.begin(), visits.end(),
              [](const auto& a, const auto& b) { return a.session < b.session; });
  }
  return data;
}

ExperiencesFigures EvalExperiences(const SessionsDataset& data,
                                   const ExperiencesEvalOptions& options) {
  options.experiences.Validate();
  options.shift.Validate();
  const features::FeatureExtractor extractor(options.shift.features);
  const auto features_of = [&](const SessionsDataset::Visit& v) {
    return extractor.Extract(io::ReadImage(v.image, cv::IMREAD_GRAYSCALE, 16));
  };
  ExperiencesFigures out;
  out.tolerance_px = options.tolerance_px;
  int visits = 0, single = 0, experiences = 0;
  for (const auto& [place, sessions] : data.places) {
    PlaceFigures figures;
    figures.place = place;
    std::vector<navigation::ExperienceView> views(1);
    views[0].features = features_of(sessions.front());
    const double origin = sessions.front().offset_px;
    for (std::size_t s = 1; s < sessions.size(); ++s) {
      const double truth = sessions[s].offset_px - origin;
      const auto within = [&](double dx) { return std::abs(dx - truth) <= options.tolerance_px; };
      features::Features current = features_of(sessions[s]);
      const features::ShiftEstimate alone =
          features::EstimateShift(views[0].features, current, options.shift);
      const navigation::ViewChoice choice = navigation::ChooseView(views, current, options.shift);
      ++figures.visits;
      figures.single_within += alone.ok && within(alone.dx_px) ? 1 : 0;
      figures.experiences_within += choice.view >= 0 && within(choice.taught_dx_px) ? 1 : 0;
      const int visit = static_cast<int>(s);
      navigation::MarkUsed(&views, choice, visit);
      if (navigation::WhyLearn(choice, options.experiences)) {
        ++figures.learned;
        figures.learned_within += within(choice.taught_dx_px) ? 1 : 0;
        navigation::LearnView(&views, choice, std::move(current), visit, options.experiences);
      }
    }
    figures.views = static_cast<int>(views.size());
    visits += figures.visits;
    single += figures.single_within;
    experiences += figures.experiences_within;
    out.learned += figures.learned;
    out.learned_within += figures.learned_within;
    out.places.push_back(figures);
  }
  out.single_fraction = Fraction(single, visits);
  out.experiences_fraction = Fraction(experiences, visits);
  return out;
}

}  // namespace mapless::eval
