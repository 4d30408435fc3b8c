// sim::score_mask: the object a mask covers most and its IoU with that object's true mask.
#include <gtest/gtest.h>

#include <stdexcept>

#include "nudge/sim/mask_score.hpp"

using nudge::sim::score_mask;

TEST(MaskScore, PicksTheObjectCoveredMostAndItsIoU) {
  cv::Mat labels(100, 100, CV_8UC1, cv::Scalar(0));
  labels(cv::Rect(10, 10, 20, 20)).setTo(1);  // object 0: 400 px
  labels(cv::Rect(50, 50, 20, 20)).setTo(3);  // object 2: 400 px
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(50, 50, 20, 10)).setTo(255);  // half of object 2
  mask(cv::Rect(10, 10, 5, 5)).setTo(7);      // a little of object 0 (any non-zero value counts)
  const auto score = score_mask(mask, labels, 3);
  EXPECT_EQ(score.object, 2);
  EXPECT_EQ(score.mask_pixels, 225);
  EXPECT_NEAR(score.iou, 200.0 / (400 + 25), 1e-12);  // overlap 200, union 400 + the 25 px off it
}

TEST(MaskScore, AMaskOnNoObjectScoresNone) {
  cv::Mat labels(40, 40, CV_8UC1, cv::Scalar(0));
  labels(cv::Rect(0, 0, 10, 10)).setTo(1);
  cv::Mat mask(40, 40, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(20, 20, 10, 10)).setTo(255);
  const auto score = score_mask(mask, labels, 1);
  EXPECT_EQ(score.object, -1);
  EXPECT_EQ(score.iou, 0);
}

TEST(MaskScore, DifferentSizesAreNamed) {
  try {
    score_mask(cv::Mat(10, 20, CV_8UC1, cv::Scalar(0)), cv::Mat(30, 40, CV_8UC1, cv::Scalar(0)), 1);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("20x10 mask against 40x30"), std::string::npos) << e.what();
  }
}
