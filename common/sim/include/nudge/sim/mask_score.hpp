#pragma once
// A segmentation mask scored against the simulator's truth in the same view: which object it
// covers most and how well (thesis §6.5's measure in simulation; nudge-report, the experiments).
#include <opencv2/core.hpp>

namespace nudge::sim {

struct MaskScore {
  int object = -1;      // scene index of the object the mask overlaps most; -1: none
  double iou = 0;       // intersection over union with that object's true mask
  int mask_pixels = 0;  // non-zero pixels of the mask
};

// `labels`: CV_8U, object index + 1, 0 elsewhere (World::render_snapshot_mask()); `mask`: CV_8U
// of the same size, non-zero where segmented; `objects`: how many objects the scene has. Throws
// std::invalid_argument naming what differs when the sizes or types do not match.
MaskScore score_mask(const cv::Mat& mask, const cv::Mat& labels, int objects);

}  // namespace nudge::sim
