// Line verification on busy images (issue 14): an object's line keeps its rank, a line between
// two objects over a textured background loses it.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/verify.hpp"

namespace sym = nudge::symmetry;

namespace {

constexpr int kWidth = 320, kHeight = 240;

// A pale yellow object (x 50..89, axis 69.5: on an R bin) on a horizontal grey ramp, and a blue and a
// green object (x 170..200 and 230..270), taller than the yellow one, whose facing sides pair up into
// a phantom at x = 215; in the gap between them a dark stripe of table texture.
cv::Mat busy_image() {
  cv::Mat image(kHeight, kWidth, CV_8UC3);
  for (int x = 0; x < kWidth; ++x) image.col(x).setTo(cv::Scalar::all(20 + (x * 200) / kWidth));
  cv::rectangle(image, cv::Rect(50, 60, 40, 140), cv::Scalar(200, 230, 255), cv::FILLED);
  cv::rectangle(image, cv::Rect(170, 15, 31, 210), cv::Scalar(200, 60, 30), cv::FILLED);
  cv::rectangle(image, cv::Rect(230, 15, 41, 210), cv::Scalar(40, 190, 40), cv::FILLED);
  cv::rectangle(image, cv::Rect(202, 15, 9, 210), cv::Scalar(20, 20, 20), cv::FILLED);
  return image;
}

double x_of(const sym::Line& line) { return line.r / std::cos(line.theta) + 0.5 * (kWidth - 1); }

const sym::Line* line_at(const std::vector<sym::Line>& lines, double x) {
  for (const auto& l : lines)
    if (std::fabs(l.theta) < 0.02 && std::fabs(x_of(l) - x) < 1.5) return &l;
  return nullptr;
}

struct Detection {
  sym::Detector detector;
  sym::EdgeSet edges;
  std::vector<sym::Line> lines;
};

Detection detect(const cv::Mat& image) {
  sym::Params params;
  params.dmin = 10;
  params.dmax = 120;
  params.num_lines = 20;
  params.theta_min_deg = -25;  // upright objects, as the supervisor's loop runs the service
  params.theta_max_deg = 25;
  params.suppress_r = 3;
  params.suppress_theta = 3;
  Detection d{sym::Detector(params), {}, {}};
  d.edges = sym::detect_edges(image, {});
  d.lines = d.detector.detect(d.edges).lines;
  return d;
}

}  // namespace

TEST(SymmetryVerify, ObjectAgreesWithItselfThePhantomDoesNot) {
  const cv::Mat image = busy_image();
  const Detection d = detect(image);
  const sym::Line* object = line_at(d.lines, 69.5);
  const sym::Line* phantom = line_at(d.lines, 215);
  ASSERT_NE(object, nullptr);
  ASSERT_NE(phantom, nullptr);
  EXPECT_GT(phantom->votes, object->votes);  // what the accumulator alone would rank first
  const sym::LineEvidence on_object = sym::line_evidence(d.detector, d.edges, image, *object);
  const sym::LineEvidence on_phantom = sym::line_evidence(d.detector, d.edges, image, *phantom);
  EXPECT_GT(on_object.appearance, 0.9);
  EXPECT_LT(on_phantom.appearance, 0.5);
  EXPECT_GT(on_object.band_share, 0.9);
  EXPECT_GT(on_object.pairs, 100);
}

TEST(SymmetryVerify, RanksTheObjectAboveThePhantomAndTrimsItsSupport) {
  const cv::Mat image = busy_image();
  const Detection d = detect(image);
  sym::VerifyParams params;
  params.keep = 20;
  std::vector<sym::LineEvidence> evidence;
  const std::vector<sym::Line> verified = sym::verify_lines(d.detector, d.edges, image, d.lines, params, &evidence);
  ASSERT_EQ(evidence.size(), verified.size());
  int object_rank = -1, phantom_rank = -1;
  for (size_t i = 0; i < verified.size(); ++i) {
    if (std::fabs(verified[i].theta) < 0.02 && std::fabs(x_of(verified[i]) - 69.5) < 1.5 && object_rank < 0) object_rank = i;
    if (std::fabs(verified[i].theta) < 0.02 && std::fabs(x_of(verified[i]) - 215) < 1.5 && phantom_rank < 0) phantom_rank = i;
  }
  ASSERT_GE(object_rank, 0);
  if (phantom_rank >= 0) {
    EXPECT_LT(object_rank, phantom_rank);
  }
  // The object's support is its own height (rows 60..199), not the whole image column.
  const sym::Line& object = verified[object_rank];
  EXPECT_NEAR(std::min(object.seg1.y, object.seg2.y), 60, 6);
  EXPECT_NEAR(std::max(object.seg1.y, object.seg2.y), 199, 6);
  params.keep = 2;
  EXPECT_EQ(sym::verify_lines(d.detector, d.edges, image, d.lines, params).size(), 2u);
}

// The pale object's outline broken for 20 rows (a stretch against a background of its own
// colour): the support segment is its larger fragment, unless support_gap_px joins the two.
TEST(SymmetryVerify, TheSupportGapJoinsABrokenOutline) {
  cv::Mat image = busy_image();
  const cv::Rect hidden(50, 130, 40, 20);
  for (int x = hidden.x; x < hidden.x + hidden.width; ++x)
    image(cv::Rect(x, hidden.y, 1, hidden.height)).setTo(cv::Scalar::all(20 + (x * 200) / kWidth));
  const Detection d = detect(image);
  sym::VerifyParams params;
  params.keep = 20;
  auto support_of_object = [&](double support_gap) {
    params.support_gap_px = support_gap;
    const sym::Line* object = nullptr;
    const std::vector<sym::Line> verified = sym::verify_lines(d.detector, d.edges, image, d.lines, params);
    object = line_at(verified, 69.5);
    EXPECT_NE(object, nullptr);
    return object ? cv::Vec2d(std::min(object->seg1.y, object->seg2.y), std::max(object->seg1.y, object->seg2.y))
                  : cv::Vec2d(0, 0);
  };
  const cv::Vec2d fragment = support_of_object(0);
  EXPECT_NEAR(fragment[0], 60, 6);   // the upper fragment, rows 60..129, is the larger
  EXPECT_NEAR(fragment[1], 130, 6);
  const cv::Vec2d whole = support_of_object(30);
  EXPECT_NEAR(whole[0], 60, 6);
  EXPECT_NEAR(whole[1], 199, 6);
  params.support_gap_px = -1;
  EXPECT_THROW(sym::validate(params), std::invalid_argument);
}

TEST(SymmetryVerify, RefusesBadInput) {
  const cv::Mat image = busy_image();
  const Detection d = detect(image);
  sym::VerifyParams bad;
  bad.colour_tolerance = -1;
  EXPECT_THROW(sym::verify_lines(d.detector, d.edges, image, d.lines, bad), std::invalid_argument);
  bad = {};
  bad.band_gap_px = 0;
  EXPECT_THROW(sym::validate(bad), std::invalid_argument);
  const cv::Mat smaller = image(cv::Rect(0, 0, 100, 100)).clone();
  EXPECT_THROW(sym::verify_lines(d.detector, d.edges, smaller, d.lines), std::invalid_argument);
}

// A peak two degrees beside the pale object's axis still collects chords of its two straight
// sides, whose midpoints lie on the axis: the refit moves the line onto the axis, the line as
// the accumulator gave it stays two degrees off.
TEST(SymmetryVerify, RefitsABesidePeakOntoTheAxis) {
  const cv::Mat image = busy_image();
  Detection d = detect(image);
  const sym::Line* object = line_at(d.lines, 69.5);
  ASSERT_NE(object, nullptr);
  sym::Line beside = *object;
  beside.theta_bin = object->theta_bin + 2;
  beside.theta = sym::theta_of_bin_deg(beside.theta_bin) * M_PI / 180;
  // Through the axis at the object's mid-height (row 130).
  beside.r = (69.5 - 0.5 * (kWidth - 1)) * std::cos(beside.theta) + (130 - 0.5 * (kHeight - 1)) * std::sin(beside.theta);
  beside.r_bin = static_cast<int>(std::lround(beside.r)) + d.detector.last_accumulator().r_max;
  sym::VerifyParams params;
  params.keep = 1;
  const std::vector<sym::Line> as_is = sym::verify_lines(d.detector, d.edges, image, {beside}, params);
  ASSERT_EQ(as_is.size(), 1u);
  EXPECT_NEAR(as_is[0].theta, 2 * M_PI / 180, 1e-9);
  params.refine = true;
  const std::vector<sym::Line> refit = sym::verify_lines(d.detector, d.edges, image, {beside}, params);
  ASSERT_EQ(refit.size(), 1u);
  EXPECT_LT(std::fabs(refit[0].theta), 0.3 * M_PI / 180);
  EXPECT_NEAR(x_of(refit[0]), 69.5, 0.5);
  // A refit that would move the line further than refine_max_deg is not taken.
  params.refine_max_deg = 1;
  EXPECT_NEAR(sym::verify_lines(d.detector, d.edges, image, {beside}, params)[0].theta, 2 * M_PI / 180, 1e-9);
}

TEST(SymmetryVerify, FitsALineThroughPoints) {
  std::vector<cv::Point2d> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(100 + 0.1 * i, 20 + 5 * i);  // steep, leaning right
  const auto line = sym::fit_line(points, kWidth, kHeight);
  ASSERT_TRUE(line.has_value());
  EXPECT_NEAR(line->theta, -std::atan(0.1 / 5), 1e-9);
  for (const auto& p : points)
    EXPECT_NEAR((p.x - 0.5 * (kWidth - 1)) * std::cos(line->theta) + (p.y - 0.5 * (kHeight - 1)) * std::sin(line->theta),
                line->r, 1e-9);
  EXPECT_FALSE(sym::fit_line({cv::Point2d(1, 1)}, kWidth, kHeight).has_value());
  EXPECT_FALSE(sym::fit_line({cv::Point2d(1, 1), cv::Point2d(1, 1)}, kWidth, kHeight).has_value());
  sym::VerifyParams bad;
  bad.refine_min_pairs = 1;
  EXPECT_THROW(sym::validate(bad), std::invalid_argument);
}
