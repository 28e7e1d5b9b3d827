#include "mapless/run/real_data.h"

#include "mapless/run/text.h"

namespace mapless::run {

SuiteOutput RunShiftEval(const std::string& dir, const eval::ShiftEvalOptions& options) {
  const eval::ShiftDataset data = eval::LoadShiftDataset(dir);
  const eval::ShiftEvalFigures f = eval::EvalShift(data, options);
  SuiteOutput out;
  out.json = {{"suite", "shift"},          {"dir", dir},
              {"layout", data.layout},     {"images", f.images},
              {"pairs", f.pairs},          {"tolerance_px", f.tolerance_px},
              {"methods", nlohmann::json::array()}};
  out.table = Format("%-10s %6s %7s %7s %9s %11s %9s %8s\n", "method", "pairs", "within", "not ok",
                     "fraction", "extract ms", "match ms", "pair ms");
  for (const auto& m : f.methods) {
    out.json["methods"].push_back({{"method", m.method},
                                   {"pairs", m.pairs},
                                   {"within", m.within},
                                   {"not_ok", m.not_ok},
                                   {"fraction", m.fraction},
                                   {"extract_ms", m.extract_ms},
                                   {"match_ms", m.match_ms},
                                   {"pair_ms", m.pair_ms}});
    out.table += Format("%-10s %6d %7d %7d %9.3f %11.2f %9.2f %8.2f\n", m.method.c_str(), m.pairs,
                        m.within, m.not_ok, m.fraction, m.extract_ms, m.match_ms, m.pair_ms);
  }
  out.table += Format(
      "%s layout, %d images: within = the shift is ok and within %.1f px of the truth; ms are\n"
      "medians on one thread (pair = both images described and matched); baselines: stock OpenCV,\n"
      "1600 keypoints, cross-checked matches, a histogram vote on dx (orb: ORB; fast_sift: FAST\n"
      "corners, SIFT descriptors)\n",
      data.layout.c_str(), f.images, f.tolerance_px);
  return out;
}

}  // namespace mapless::run
