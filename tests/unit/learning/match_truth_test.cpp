// The learning experiment's good/bad match rule on hand-made surface truth.
#include <gtest/gtest.h>

#include <cmath>

#include "nudge/learning/match_truth.hpp"

using namespace nudge::learning;

namespace {

// A 20x10 image: object label 1 in columns 0..9, whose surface x coordinate is column * 1 mm;
// nothing (NaN, label 0) in columns 10..19.
SurfaceTruth strip(const std::string& object, float shift_m = 0) {
  SurfaceTruth t;
  t.mask = cv::Mat::zeros(10, 20, CV_8U);
  const float nan = std::nanf("");
  t.surface = cv::Mat(10, 20, CV_32FC3, cv::Scalar(nan, nan, nan));
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      t.mask.at<uint8_t>(y, x) = 1;
      t.surface.at<cv::Vec3f>(y, x) = cv::Vec3f(x * 0.001f + shift_m, 0.02f, 0.05f);
    }
  t.label = 1;
  t.object = object;
  return t;
}

std::vector<cv::KeyPoint> at(std::initializer_list<cv::Point2f> points) {
  std::vector<cv::KeyPoint> out;
  for (const auto& p : points) out.emplace_back(p, 4.f);
  return out;
}

}  // namespace

TEST(MatchTruth, SurfacePointTakesTheNearestObjectPixelWithinOnePixel) {
  const SurfaceTruth t = strip("bottle");
  ASSERT_TRUE(surface_point(t, {3.2f, 5.f}));
  EXPECT_NEAR((*surface_point(t, {3.2f, 5.f}))[0], 0.003, 1e-6);
  // Just off the silhouette: column 10 is empty, column 9 is one pixel away.
  ASSERT_TRUE(surface_point(t, {10.4f, 5.f}));
  EXPECT_NEAR((*surface_point(t, {10.4f, 5.f}))[0], 0.009, 1e-6);
  EXPECT_FALSE(surface_point(t, {12.f, 5.f}));   // two pixels off: not on the object
  EXPECT_FALSE(surface_point(t, {-5.f, 50.f}));  // outside the image
}

TEST(MatchTruth, SamePointIsGoodOtherPointOrOffObjectIsBad) {
  const SurfaceTruth query = strip("bottle");
  // The training view sees the same strip shifted by 2 pixels: its column x shows query column x + 2.
  const SurfaceTruth training = strip("bottle", 0.002f);
  const auto query_points = at({{5, 5}, {5, 5}, {2, 2}, {15, 5}});
  const auto training_points = at({{3, 5}, {8, 5}, {0.4f, 2}, {3, 5}});
  const std::vector<cv::DMatch> matches = {{0, 0, 0.f},   // same point: good
                                           {1, 1, 0.f},   // 5 mm apart: bad at 3 mm
                                           {2, 2, 0.f},   // 0.4 mm apart: good
                                           {3, 3, 0.f}};  // query point off the object: bad
  const MatchVerdicts v = judge_matches(matches, query_points, query, training_points, training, 0.003);
  EXPECT_EQ(v.good, 2);
  EXPECT_EQ(v.bad, 2);
  ASSERT_EQ(v.distances_m.size(), 3u);
  EXPECT_NEAR(v.distances_m[0], 0.0, 1e-6);
  EXPECT_NEAR(v.distances_m[1], 0.005, 1e-6);
  // A looser tolerance takes the 5 mm match too.
  EXPECT_EQ(judge_matches(matches, query_points, query, training_points, training, 0.006).good, 3);
}

TEST(MatchTruth, AnotherObjectsSurfaceIsNeverAGoodMatch) {
  const SurfaceTruth query = strip("white_bottle"), training = strip("green_bottle");
  const auto points = at({{4, 4}});
  const MatchVerdicts v = judge_matches({{0, 0, 0.f}}, points, query, points, training, 0.003);
  EXPECT_EQ(v.good, 0);
  EXPECT_EQ(v.bad, 1);
}

TEST(MatchTruth, AnIndexOutsideTheKeypointsThrows) {
  const SurfaceTruth t = strip("bottle");
  EXPECT_THROW(judge_matches({{3, 0, 0.f}}, at({{1, 1}}), t, at({{1, 1}}), t, 0.003), std::out_of_range);
}
