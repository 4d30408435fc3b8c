#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/synthetic.hpp"

using namespace nudge::segmentation;
namespace sym = nudge::symmetry;
namespace syn = nudge::symmetry::synthetic;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kWidth = 320, kHeight = 240;

double distance_to_segment(const cv::Point2d& p, const cv::Point2d& a, const cv::Point2d& b) {
  const cv::Point2d ab = b - a;
  const double len2 = ab.dot(ab);
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + t * ab));
}

double distance_to_polyline(const cv::Point2d& p, const std::vector<cv::Point2d>& line, bool closed) {
  double best = 1e300;
  if (line.size() == 1) return cv::norm(p - line[0]);
  const size_t n = line.size();
  for (size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i)
    best = std::min(best, distance_to_segment(p, line[i], line[(i + 1) % n]));
  return best;
}

// Points every ~0.5 px along a closed polygon.
std::vector<cv::Point2d> densify(const std::vector<cv::Point2d>& polygon) {
  std::vector<cv::Point2d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const cv::Point2d a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil(2 * cv::norm(b - a))));
    for (int k = 0; k < steps; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / steps));
  }
  return out;
}

// Fraction of the true outline lying within `tolerance` px of the contour (either side).
double outline_coverage(const std::vector<cv::Point2d>& truth, const Contour& contour, double tolerance) {
  const std::vector<cv::Point2d> samples = densify(truth);
  int covered = 0;
  for (const auto& p : samples) {
    if (distance_to_polyline(p, contour.left, false) <= tolerance ||
        distance_to_polyline(p, contour.right, false) <= tolerance)
      ++covered;
  }
  return static_cast<double>(covered) / samples.size();
}

// Fraction of contour points lying within `tolerance` px of the true outline.
double contour_precision(const std::vector<cv::Point2d>& truth, const Contour& contour, double tolerance) {
  int near = 0, total = 0;
  for (const auto* side : {&contour.left, &contour.right}) {
    for (const auto& p : *side) {
      ++total;
      if (distance_to_polyline(p, truth, true) <= tolerance) ++near;
    }
  }
  return total ? static_cast<double>(near) / total : 0.0;
}

struct Scene {
  cv::Mat image;
  std::vector<cv::Point2d> outline;
  sym::Line line;
};

Scene make_scene(const syn::Profile& profile, double r, double theta_deg, double along) {
  Scene s;
  s.image = cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(200));
  s.line.r = r;
  s.line.theta = theta_deg * kDeg;
  syn::draw_shape(s.image, profile, r, s.line.theta, along, cv::Scalar(70));
  s.outline = syn::outline(profile, r, s.line.theta, along, kWidth, kHeight);
  return s;
}

cv::Mat canny(const cv::Mat& image) {
  cv::Mat edges;
  cv::Canny(image, edges, 30, 90, 3);
  return edges;
}

// Knocks holes into the edge image and sprinkles noise edge pixels over it.
void damage(cv::Mat& edges, const std::vector<cv::Rect>& gaps, int noise_pixels, uint32_t seed) {
  for (const cv::Rect& gap : gaps) edges(gap & cv::Rect(0, 0, edges.cols, edges.rows)).setTo(0);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, edges.cols - 1), y(0, edges.rows - 1);
  for (int i = 0; i < noise_pixels; ++i) edges.at<uint8_t>(y(rng), x(rng)) = 255;
}

void expect_good_contour(const Scene& scene, const cv::Mat& edges, const SegmentParams& params = {}) {
  const Contour contour = Segmenter(params).segment(edges, scene.line);
  ASSERT_FALSE(contour.empty());
  EXPECT_GT(contour.score, 0);
  EXPECT_GE(outline_coverage(scene.outline, contour, 2.0), 0.9);
  EXPECT_GE(contour_precision(scene.outline, contour, 2.0), 0.9);
}

}  // namespace

TEST(SegmentationSept, WeightsFollowAlgorithm2) {
  // One row, line at x = 10 (theta = 0): pairs (4, 16) and (5, 17) both have width 12; the first is
  // exactly symmetric (d = 0, W = 1), the second has d = 1 (W = 1 - 1/(2*3)).
  sym::EdgeSet edges;
  edges.width = 21;
  edges.height = 3;
  edges.points = {{4, 1}, {5, 1}, {16, 1}, {17, 1}};
  sym::Line line;
  line.r = 10 - 0.5 * (edges.width - 1);
  SegmentParams params;
  params.max_mid = 3;
  params.max_width = 40;
  const SeptBuffer sept = Segmenter(params).sept(edges, line);
  ASSERT_EQ(sept.weights.cols, 21);
  const int row = 0 - sept.first_row;  // image row 1 is v = 1 - (h - 1) / 2 = 0
  // (4,16), (5,17) and (5,16) (w 11, ceil(5.5) = 6) share cell 6: the exactly symmetric pair wins.
  EXPECT_FLOAT_EQ(sept.weights.at<float>(row, 6), 1.0f);
  EXPECT_FLOAT_EQ(sept.weights.at<float>(row, 7), 1.0f - 0.5f / 6);  // (4,17): w 13, d 0.5
  EXPECT_FLOAT_EQ(sept.weights.at<float>(row, 5), -1.0f);
  EXPECT_FLOAT_EQ(sept.weights.at<float>(row, 1), -1.0f);          // (4,5): d = 5.5 >= MAXmid
  EXPECT_FLOAT_EQ(sept.weights.at<float>(0, 6), -1.0f);            // empty row
  EXPECT_EQ(sept.num_pairs, 6);
}

TEST(SegmentationSept, RejectsPairsWiderThanMaxWidth) {
  sym::EdgeSet edges;
  edges.width = 101;
  edges.height = 1;
  edges.points = {{10, 0}, {90, 0}};
  sym::Line line;  // through x = 50
  SegmentParams params;
  params.max_width = 60;
  const SeptBuffer sept = Segmenter(params).sept(edges, line);
  EXPECT_EQ(cv::countNonZero(sept.weights >= 0), 0);
  params.max_width = 100;
  EXPECT_FLOAT_EQ(Segmenter(params).sept(edges, line).weights.at<float>(-sept.first_row, 40), 1.0f);
}

TEST(SegmentationSept, PairsExactlyAtTheLimitsAreInsideOrOutAsAlgorithm2Says) {
  // Line at x = 50; the pair (10, 90) is exactly MAXw = 80 wide: kept (width <= MAXw), one pixel
  // narrower a limit drops it. A pair whose midpoint is exactly MAXmid off the line is dropped
  // (d < MAXmid), a hair closer it is kept with weight 1 - d / (2 MAXmid).
  sym::EdgeSet edges;
  edges.width = 101;
  edges.height = 1;
  edges.points = {{10, 0}, {90, 0}};
  sym::Line line;
  SegmentParams params;
  params.max_width = 80;
  SeptBuffer sept = Segmenter(params).sept(edges, line);
  EXPECT_EQ(sept.num_pairs, 1);
  EXPECT_FLOAT_EQ(sept.weights.at<float>(-sept.first_row, 40), 1.0f);
  params.max_width = 79;
  sept = Segmenter(params).sept(edges, line);
  EXPECT_EQ(sept.num_pairs, 0);
  EXPECT_EQ(cv::countNonZero(sept.weights >= 0), 0);

  edges.points = {{40, 0}, {80, 0}};  // midpoint 60: d = 10
  params.max_width = 80;
  params.max_mid = 10;
  sept = Segmenter(params).sept(edges, line);
  EXPECT_EQ(sept.num_pairs, 1);
  EXPECT_EQ(cv::countNonZero(sept.weights >= 0), 0);
  params.max_mid = 10.5;
  sept = Segmenter(params).sept(edges, line);
  EXPECT_FLOAT_EQ(sept.weights.at<float>(-sept.first_row, 20), static_cast<float>(1.0 - 10 / 21.0));
}

TEST(SegmentationDp, PrefersTallContourAndBridgesGaps) {
  // A column of weights at half-width 5 over rows 2..29 with a gap at rows 12..15, a flat wide run
  // in row 20, and an isolated cell. The contour must be the tall column.
  cv::Mat sept(32, 20, CV_32F, cv::Scalar(-1));
  for (int r = 2; r < 30; ++r)
    if (r < 12 || r > 15) sept.at<float>(r, 5) = 1.0f;
  for (int c = 8; c < 20; ++c) sept.at<float>(20, c) = 1.0f;
  sept.at<float>(25, 15) = 1.0f;
  double score = 0;
  const std::vector<Cell> path = Segmenter().best_path(sept, &score);
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.front().row, 2);
  EXPECT_EQ(path.back().row, 29);
  for (const Cell& cell : path) EXPECT_EQ(cell.column, 5);
  EXPECT_NEAR(score, 24 * 1.0 + 4 * -0.5, 1e-9);
}

TEST(SegmentationDp, GapsCostTheVerticalPenaltyPerRow) {
  // PrefersTallContourAndBridgesGaps with Pver != Phor: the 4-row gap costs 4 Pver, not 4 Phor.
  cv::Mat sept(32, 20, CV_32F, cv::Scalar(-1));
  for (int r = 2; r < 30; ++r)
    if (r < 12 || r > 15) sept.at<float>(r, 5) = 1.0f;
  SegmentParams params;
  params.penalty_vertical = -2.0;
  params.penalty_horizontal = -0.3;
  double score = 0;
  const std::vector<Cell> path = Segmenter(params).best_path(sept, &score);
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.front().row, 2);  // 10 - 8 > 0: the gap is still bridged
  EXPECT_EQ(path.back().row, 29);
  EXPECT_NEAR(score, 24 * 1.0 + 4 * -2.0, 1e-9);
}

TEST(SegmentationDp, FollowsHorizontalRunsWithoutCycles) {
  // A U shape: a horizontal bottom run joined to two... one side only (half-width columns): top run
  // from column 1 to 6 in row 0, down column 6, bottom run back to column 1.
  cv::Mat sept(12, 10, CV_32F, cv::Scalar(-1));
  for (int c = 1; c <= 6; ++c) sept.at<float>(0, c) = sept.at<float>(11, c) = 1.0f;
  for (int r = 0; r <= 11; ++r) sept.at<float>(r, 6) = 1.0f;
  double score = 0;
  const std::vector<Cell> path = Segmenter().best_path(sept, &score);
  ASSERT_EQ(path.size(), 6u + 10u + 6u);
  EXPECT_EQ(path.front().row, 0);
  EXPECT_EQ(path.front().column, 1);
  EXPECT_EQ(path.back().row, 11);
  EXPECT_EQ(path.back().column, 1);
  EXPECT_NEAR(score, 1.0 + 5 * 0.5 + 11 * 1.0 + 5 * 0.5, 1e-9);
}

TEST(SegmentationDp, EmptyBufferGivesEmptyContour) {
  const cv::Mat sept(10, 10, CV_32F, cv::Scalar(-1));
  double score = 1;
  EXPECT_TRUE(Segmenter().best_path(sept, &score).empty());
  EXPECT_EQ(score, 0);
  sym::EdgeSet edges;
  edges.width = 50;
  edges.height = 40;
  EXPECT_TRUE(segment(edges, sym::Line{}).empty());
}

TEST(Segmentation, CleanBottleAndCup) {
  const Scene bottle = make_scene(syn::bottle_profile(180, 35), 10, 0, 0);
  expect_good_contour(bottle, canny(bottle.image));
  const Scene cup = make_scene(syn::cup_profile(120, 50, 38), -20, 0, 10);
  expect_good_contour(cup, canny(cup.image));
}

TEST(Segmentation, TiltedAxes) {
  for (double theta_deg : {-20.0, -8.0, 5.0, 15.0, 25.0}) {
    SCOPED_TRACE(theta_deg);
    const Scene bottle = make_scene(syn::bottle_profile(170, 32), 5, theta_deg, -5);
    expect_good_contour(bottle, canny(bottle.image));
    const Scene cup = make_scene(syn::cup_profile(110, 48, 36), -15, theta_deg, 0);
    expect_good_contour(cup, canny(cup.image));
  }
}

TEST(Segmentation, GapsAndNoiseEdgePixels) {
  const Scene bottle = make_scene(syn::bottle_profile(180, 35), 0, 0, 0);
  cv::Mat edges = canny(bottle.image);
  // Gaps: 8 px of the left side, 6 px of the right side at another height, a hole in the base.
  const double cx = 0.5 * (kWidth - 1), cy = 0.5 * (kHeight - 1);
  damage(edges,
         {cv::Rect(static_cast<int>(cx - 40), static_cast<int>(cy + 20), 10, 8),
          cv::Rect(static_cast<int>(cx + 30), static_cast<int>(cy - 10), 10, 6),
          cv::Rect(static_cast<int>(cx - 10), static_cast<int>(cy + 85), 12, 10)},
         600, 7);
  expect_good_contour(bottle, edges);

  const Scene cup = make_scene(syn::cup_profile(120, 50, 38), 0, 12, 0);
  cv::Mat cup_edges = canny(cup.image);
  damage(cup_edges, {cv::Rect(static_cast<int>(cx + 35), static_cast<int>(cy - 5), 15, 10)}, 600, 11);
  expect_good_contour(cup, cup_edges);
}

TEST(Segmentation, OccludingBlob) {
  Scene bottle = make_scene(syn::bottle_profile(180, 35), 0, 6, 0);
  // A blob of another grey level across the right side of the body.
  const cv::Point2d pivot(0.5 * (kWidth - 1), 0.5 * (kHeight - 1));
  const cv::Point2d normal(std::cos(bottle.line.theta), std::sin(bottle.line.theta));
  const cv::Point2d direction(-normal.y, normal.x);
  const cv::Point2d centre = pivot + 35 * normal + 30 * direction;
  cv::circle(bottle.image, cv::Point(static_cast<int>(centre.x), static_cast<int>(centre.y)), 12,
             cv::Scalar(130), cv::FILLED, cv::LINE_AA);
  cv::Mat edges = canny(bottle.image);
  damage(edges, {}, 400, 3);
  expect_good_contour(bottle, edges);
}

TEST(Segmentation, RefinementSnapsOntoEdgePixels) {
  const Scene cup = make_scene(syn::cup_profile(120, 50, 38), 0, 10, 0);
  const cv::Mat edges = canny(cup.image);
  const Contour contour = segment(sym::edges_from_mask(edges), cup.line);
  ASSERT_FALSE(contour.empty());
  int on_edge = 0;
  for (const auto* side : {&contour.left, &contour.right})
    for (const auto& p : *side) on_edge += edges.at<uint8_t>(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y))) ? 1 : 0;
  EXPECT_GE(on_edge, static_cast<int>(0.95 * 2 * contour.cells.size()));

  SegmentParams raw;
  raw.refine = false;
  const Contour unrefined = segment(sym::edges_from_mask(edges), cup.line, raw);
  EXPECT_EQ(unrefined.cells.size(), contour.cells.size());
  EXPECT_GE(outline_coverage(cup.outline, unrefined, 2.5), 0.85);
}

TEST(Segmentation, UnrefinedContourLiesOnTheEdgePixelsRows) {
  // Edge pixels at x = 40 and 60 on rows 10..30, line x = 50: without refinement the contour's
  // points are placed from the SEPT cells alone, exactly on those pixels.
  sym::EdgeSet edges;
  edges.width = 101;
  edges.height = 41;
  for (int y = 10; y <= 30; ++y) {
    edges.points.push_back({40, y});
    edges.points.push_back({60, y});
  }
  sym::Line line;  // x = 50
  SegmentParams params;
  params.refine = false;
  const Contour contour = Segmenter(params).segment(edges, line);
  ASSERT_EQ(contour.left.size(), 21u);
  ASSERT_EQ(contour.right.size(), 21u);
  for (size_t i = 0; i < contour.left.size(); ++i) {
    EXPECT_NEAR(contour.left[i].y, 10 + static_cast<double>(i), 1e-9);
    EXPECT_NEAR(contour.right[i].y, 10 + static_cast<double>(i), 1e-9);
    EXPECT_NEAR(std::min(contour.left[i].x, contour.right[i].x), 40, 1e-9);
    EXPECT_NEAR(std::max(contour.left[i].x, contour.right[i].x), 60, 1e-9);
  }
}

TEST(Segmentation, MaskAndDrawing) {
  const Scene cup = make_scene(syn::cup_profile(120, 50, 38), 0, 0, 0);
  const Contour contour = Segmenter().segment(canny(cup.image), cup.line);
  const cv::Mat mask = contour_mask(contour, cup.image.size());
  cv::Mat truth = cv::Mat::zeros(cup.image.size(), CV_8U);
  syn::draw_shape(truth, syn::cup_profile(120, 50, 38), 0, 0, 0, cv::Scalar(255));
  const double inter = cv::countNonZero(mask & truth), uni = cv::countNonZero(mask | truth);
  EXPECT_GT(inter / uni, 0.95);
  const cv::Mat picture = draw_contour(cup.image, contour, cup.line);
  EXPECT_EQ(picture.type(), CV_8UC3);
  EXPECT_EQ(picture.size(), cup.image.size());
}

TEST(Segmentation, InvalidInput) {
  SegmentParams bad;
  bad.reward_horizontal = 2.0;  // Rhor must stay below Rver
  EXPECT_THROW(Segmenter{bad}, std::invalid_argument);
  bad = SegmentParams{};
  bad.max_mid = 0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  EXPECT_THROW(Segmenter().segment(cv::Mat(), sym::Line{}), std::invalid_argument);
  EXPECT_THROW(Segmenter().segment(sym::EdgeSet{}, sym::Line{}), std::invalid_argument);
}

TEST(Segmentation, WithDetectedLine) {
  // The whole monocular chain: fast symmetry detection (ch. 3) picks the line, then segmentation.
  const Scene bottle = make_scene(syn::bottle_profile(180, 35), 12, 4, 0);
  sym::Params params;
  params.dmin = 10;
  params.dmax = 0;
  params.num_lines = 1;
  sym::Detector detector(params);
  const sym::Result result = detector.detect(bottle.image);
  ASSERT_EQ(result.lines.size(), 1u);
  EXPECT_NEAR(result.lines[0].theta, bottle.line.theta, 1.0 * kDeg);
  expect_good_contour(Scene{bottle.image, bottle.outline, result.lines[0]}, canny(bottle.image));
}
