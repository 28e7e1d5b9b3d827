// The evaluations on a user's real images (issue 66): `mapless eval shift`, `eval localize` and
// `eval ground`. Each prints mapless's figure and stock baselines computed in the same run on the
// same images, with the cost per item; the layouts are in docs/real_data.md.
#pragma once

#include <string>

#include "mapless/eval/real_ground.h"
#include "mapless/eval/real_localize.h"
#include "mapless/eval/real_shift.h"
#include "mapless/run/suites.h"

namespace mapless::run {

// {"suite": "shift", "dir", "layout", "images", "pairs", "tolerance_px", "methods": [{"method",
// "pairs", "within", "not_ok", "fraction", "extract_ms", "match_ms", "pair_ms"}]}; mapless first.
SuiteOutput RunShiftEval(const std::string& dir, const eval::ShiftEvalOptions& options);

// {"suite": "localize", "database", "query", "database_images", "queries", "methods": [{"method",
// "queries", "within0", "within1", "within5", "within10", "recall_at_full_precision" (null: no
// confidence), "query_ms"}]}; mapless first.
SuiteOutput RunLocalizeEval(const std::string& database, const std::string& query,
                            const eval::LocalizeEvalOptions& options);

// {"suite": "ground", "frames", "masks", "pairs", "flow_ms", "methods": [{"method", "pairs",
// "mean_iou", "plane_ms"}]}; mapless first.
SuiteOutput RunGroundEval(const std::string& frames, const std::string& masks,
                          const eval::GroundEvalOptions& options);

}  // namespace mapless::run
