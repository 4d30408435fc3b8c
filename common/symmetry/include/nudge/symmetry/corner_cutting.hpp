#pragma once
// A speed baseline, not a detector to use: voting with the shortcuts of the thesis author's own
// published C++ (the cvaddon library, 2008), written afresh from their description:
//  * floating-point rotation straight into fixed-capacity rows of Rot (no sorting);
//  * rows with at least twice the mean number of pixels are dropped (straight-line rejection);
//  * a row is scanned from each pixel onwards only until the first partner outside [Dmin, Dmax],
//    although rows are not sorted, so many valid pairs are never seen.
// It is fast because it casts only some of Algorithm 1's votes. The benchmark and the Table 3.1
// experiment time it beside the exact fast voting (Detector::vote), which casts all of them, and
// report how many votes it cast.
#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry {

class CornerCuttingVoter {
 public:
  // Same accumulator layout as Detector::vote (180 x (2 r_max + 1), bilateral layer only).
  // Throws std::invalid_argument for skew angles or the mirror rule (not part of the baseline).
  const Accumulator& vote(const EdgeSet& edges, const Params& params);

 private:
  std::vector<float> rows_;  // num_rows x capacity rotated x coordinates
  std::vector<int> fill_;    // pixels in each row
  Accumulator acc_;
};

}  // namespace nudge::symmetry
