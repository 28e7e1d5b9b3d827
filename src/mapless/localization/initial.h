// Initial localization by clustering (Section 4 of Payá et al., Fig. 6). Markov localization needs
// a good first estimate, so before it starts the robot makes small turns and moves around its
// start and localizes each image by its nearest projection. The localizations are grouped on the
// fly: each joins the cluster whose centre is nearest, or starts a new one when that centre is
// further than a threshold; a joined cluster's centre is updated. Clusters with few members are
// discarded and the one whose members lie closest together (lowest variance of their distance to
// the centre) is chosen; its centre is the initial position.
#pragma once

#include <string>
#include <vector>

namespace mapless::localization {

struct ClusteringOptions {
  double join_distance_images = 4.0;  // a localization further than this from every centre
                                      // starts a new cluster, route images
  // "Groups with few images are discarded": those with fewer members than this fraction of the
  // largest group (and single images).
  double min_member_fraction = 0.5;
  void Validate() const;
};

struct Cluster {
  double centre = 0.0;       // route index (mean of the members)
  std::vector<int> members;  // localizations (route indices)
  double variance = 0.0;     // of the members' distance to the centre, images²
};

struct InitialLocalization {
  bool ok = false;
  std::string reason;  // when !ok
  int index = -1;      // route image of the chosen cluster's centre
  int chosen = -1;     // which cluster
  std::vector<Cluster> clusters;
};

// `localizations`: the nearest-projection route index of each image taken around the start.
InitialLocalization LocalizeByClustering(const std::vector<int>& localizations,
                                         const ClusteringOptions& options);

}  // namespace mapless::localization
