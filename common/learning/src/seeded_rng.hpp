#pragma once
// Reproducible randomness for OpenCV calls that draw from the thread's global generators.
#include <opencv2/core.hpp>

#include <cstdint>
#include <cstdlib>

namespace nudge::learning::detail {

// Sets cv::theRNG() to `seed` for its lifetime and puts the caller's state back after; seeds
// std::rand() too (its state cannot be read back). RANSAC (estimateAffine2D, findHomography) and
// FLANN's randomised k-d trees draw from cv::theRNG(), FLANN's shuffle from std::rand(), so without
// a seed the same matches or descriptors give other inliers or another index depending on what the
// thread did before: a close call between two objects could then go either way from run to run.
class SeededThreadRng {
 public:
  explicit SeededThreadRng(uint64_t seed) : saved_(cv::theRNG().state) {
    cv::theRNG().state = seed;
    std::srand(static_cast<unsigned>(seed));
  }
  ~SeededThreadRng() { cv::theRNG().state = saved_; }
  SeededThreadRng(const SeededThreadRng&) = delete;
  SeededThreadRng& operator=(const SeededThreadRng&) = delete;

 private:
  uint64_t saved_;
};

}  // namespace nudge::learning::detail
