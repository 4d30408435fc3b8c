#pragma once
// The supervisor's segmentation step: common/segmentation's motion segmentation (thesis sec. 6.4)
// with fig. 6.7's stages kept for the run's files.
#include "nudge/segmentation/motion.hpp"
#include "nudge/supervisor/supervisor.hpp"

namespace nudge::supervisor {

SegmentFunction motion_segmentation(segmentation::MotionParams params = {});

}  // namespace nudge::supervisor
