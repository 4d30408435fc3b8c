#pragma once
// Shared by the learning experiments (learning_box, learning): how long recognition takes against a
// database of a given size, measured the same way in each.
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "nudge/learning/recognizer.hpp"

namespace nudge::experiments {

struct RecognitionTiming {
  std::string matcher;
  int runs = 0;
  double median_ms = 0;      // wall clock (Recognition::elapsed_ms: SIFT of the image included)
  double median_cpu_ms = 0;  // this process's CPU time: what a shared, loaded machine distorts least
  std::string label;         // the answer ("" when nothing was recognised)
};

// Recognises `image` against `objects` with the default parameters but `matcher`, `runs` times;
// medians.
RecognitionTiming time_recognition(const std::vector<std::shared_ptr<const learning::ObjectModel>>& objects,
                                   const cv::Mat& image, learning::MatcherKind matcher, int runs);

// The 1-minute load average, to say how shared the machine was while timing.
std::string load_average();

}  // namespace nudge::experiments
