#pragma once
// The supervisor's segmentation step: common/segmentation's motion segmentation (thesis sec. 6.4)
// with fig. 6.7's stages kept for the run's files.
#include "nudge/segmentation/motion.hpp"
#include "nudge/supervisor/supervisor.hpp"

namespace nudge::supervisor {

// `keep_stages`: fig. 6.7's stages in Segmentation::stages (the right camera's, written with the
// attempt). They cost a whole-image difference and copies of both stills (a fifth of the
// segmentation's time, grasp_plan_bench): the left camera's, never written, go without.
SegmentFunction motion_segmentation(segmentation::MotionParams params = {}, bool keep_stages = true);

}  // namespace nudge::supervisor
