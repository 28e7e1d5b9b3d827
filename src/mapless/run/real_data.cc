#include "mapless/run/real_data.h"

#include "mapless/run/text.h"

namespace mapless::run {

SuiteOutput RunShiftEval(const std::string& dir, const eval::ShiftEvalOptions& options) {
  const eval::ShiftDataset data = eval::LoadShiftDataset(dir);
  const eval::ShiftEvalFigures f = eval::EvalShift(data, options);
  SuiteOutput out;
  out.json = {{"suite", "shift"},
              {"dir", dir},
              {"layout", data.layout},
              {"images", f.images},
              {"pairs", f.pairs},
              {"tolerance_px", f.tolerance_px},
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

SuiteOutput RunLocalizeEval(const std::string& database, const std::string& query,
                            const eval::LocalizeEvalOptions& options) {
  const eval::LocalizeEvalFigures f = eval::EvalLocalize(database, query, options);
  SuiteOutput out;
  out.json = {{"suite", "localize"},
              {"database", database},
              {"query", query},
              {"queries", f.queries},
              {"database_images", f.database},
              {"methods", nlohmann::json::array()}};
  out.table = Format("%-12s %7s %7s %7s %7s %8s %9s %9s\n", "method", "queries", "exact", "+-1",
                     "+-5", "+-10", "recall@P1", "query ms");
  for (const auto& m : f.methods) {
    nlohmann::json recall = nullptr;
    if (m.recall_at_full_precision >= 0.0) recall = m.recall_at_full_precision;
    out.json["methods"].push_back({{"method", m.method},
                                   {"queries", m.queries},
                                   {"within0", m.within0},
                                   {"within1", m.within1},
                                   {"within5", m.within5},
                                   {"within10", m.within10},
                                   {"recall_at_full_precision", recall},
                                   {"query_ms", m.query_ms}});
    const std::string r =
        m.recall_at_full_precision >= 0.0 ? Format("%.3f", m.recall_at_full_precision) : "-";
    out.table +=
        Format("%-12s %7d %7.3f %7.3f %7.3f %8.3f %9s %9.3f\n", m.method.c_str(), m.queries,
               m.within0, m.within1, m.within5, m.within10, r.c_str(), m.query_ms);
  }
  out.table +=
      "fraction of queries within 0, 1, 5 and 10 places of the truth (the database image of the\n"
      "same name), past queries only; recall@P1: the largest fraction of queries accepted by the\n"
      "method's own confidence before the first one more than 5 places off; query ms: median per\n"
      "query on one thread (markov_pca, nearest_pca: mean), the route's preparation not counted\n";
  return out;
}

SuiteOutput RunGroundEval(const std::string& frames, const std::string& masks,
                          const eval::GroundEvalOptions& options) {
  const eval::GroundEvalFigures f = eval::EvalGround(frames, masks, options);
  SuiteOutput out;
  out.json = {{"suite", "ground"}, {"frames", frames},     {"masks", masks},
              {"pairs", f.pairs},  {"flow_ms", f.flow_ms}, {"methods", nlohmann::json::array()}};
  out.table = Format("%-18s %6s %9s %9s\n", "method", "pairs", "mean IoU", "plane ms");
  for (const auto& m : f.methods) {
    out.json["methods"].push_back({{"method", m.method},
                                   {"pairs", m.pairs},
                                   {"mean_iou", m.mean_iou},
                                   {"plane_ms", m.plane_ms}});
    out.table +=
        Format("%-18s %6d %9.3f %9.2f\n", m.method.c_str(), m.pairs, m.mean_iou, m.plane_ms);
  }
  out.table += Format(
      "IoU of the ground with the labelled mask over the bottom half, mean over the frames that\n"
      "have a mask and a next frame; both methods on the same DIS-medium flow (median %.2f ms a\n"
      "pair); ransac_homography: cv::findHomography (RANSAC, 3 px) on the flow of the bottom "
      "half,\n"
      "the ground where the flow fits it within 3 px; plane ms: median per pair, one thread\n",
      f.flow_ms);
  return out;
}

}  // namespace mapless::run
