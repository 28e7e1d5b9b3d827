// `mapless eval localize` (issue 66): a traversal (query images) localized on a route of database
// images taken in another season, by mapless and by baselines on the same images in the same run.
// Layout: two folders of images; each is a traversal in file-name order, and a query's true place
// is the database image with the same file name (the Nordland convention). Only past queries are
// used by every method.
#pragma once

#include <string>
#include <vector>

#include "mapless/localization/sequence_filter.h"

namespace mapless::eval {

struct LocalizeMethodFigures {
  std::string method;
  int queries = 0;
  // Fraction of queries localized within 0, 1, 5 and 10 places of the truth.
  double within0 = 0.0, within1 = 0.0, within5 = 0.0, within10 = 0.0;
  // Queries sorted by the method's own confidence: the largest fraction of all queries that can
  // be accepted before the first one more than 5 places off (-1: the method has no confidence).
  double recall_at_full_precision = -1.0;
  double query_ms = 0.0;  // median per query, one thread (the route's preparation not counted)
};

struct LocalizeEvalFigures {
  int database = 0;
  int queries = 0;
  std::vector<LocalizeMethodFigures> methods;  // mapless first
};

struct LocalizeEvalOptions {
  localization::SequenceFilterOptions filter;
  int pca_dimensions = 16;  // the paper's Markov localization and nearest projection
  int seqslam_length = 40;  // the SeqSLAM-style baseline: past queries in a sequence
  bool baselines = true;
};

// Reads both folders (checking every image first) and evaluates.
LocalizeEvalFigures EvalLocalize(const std::string& database_dir, const std::string& query_dir,
                                 const LocalizeEvalOptions& options);

// From per-query (confidence, correct): the largest fraction of queries accepted, highest
// confidence first, before the first incorrect one. Pure, for tests.
double RecallAtFullPrecision(std::vector<std::pair<double, bool>> scored);

}  // namespace mapless::eval
