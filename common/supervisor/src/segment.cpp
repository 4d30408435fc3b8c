#include "nudge/supervisor/segment.hpp"

#include <memory>

namespace nudge::supervisor {

SegmentFunction motion_segmentation(segmentation::MotionParams params, bool keep_stages) {
  // One segmenter kept for the run: its scratch images are reused between attempts.
  auto segmenter = std::make_shared<segmentation::MotionSegmenter>(params);
  return [segmenter, keep_stages](const cv::Mat& before, const cv::Mat& after, const symmetry::Line& before_line,
                     const symmetry::Line& after_line) {
    Segmentation out;
    segmentation::MotionStages stages;
    try {
      const segmentation::MotionSegmentation result = segmenter->segment(before, after, before_line, after_line, keep_stages ? &stages : nullptr);
      if (!result.found) out.error = result.reason;
      out.mask = result.mask;
    } catch (const std::invalid_argument& e) {
      out.error = e.what();
      return out;
    }
    if (!keep_stages) return out;
    out.stages = {{"c_difference", stages.difference}, {"d_compressed", stages.compressed},
                  {"e_refined", stages.refined}, {"e_mask_line_frame", stages.line_frame_mask}};
    return out;
  };
}

}  // namespace nudge::supervisor
