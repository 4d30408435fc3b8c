// Motion segmentation (thesis sec. 6.4) on synthetic nudges: a textured cup on a textured
// background moved by a known amount, so the object's true mask in the after image is known.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "nudge/segmentation/motion.hpp"
#include "nudge/symmetry/synthetic.hpp"

using namespace nudge::segmentation;
namespace sym = nudge::symmetry;
namespace syn = nudge::symmetry::synthetic;

namespace {

constexpr double kDeg = M_PI / 180.0;

sym::Line make_line(double r, double theta) {
  sym::Line line;
  line.r = r;
  line.theta = theta;
  return line;
}

// Smooth random texture: coarse uniform noise blown up, plus fine noise.
cv::Mat texture(cv::Size size, uint64_t seed, double low, double high, int coarseness) {
  cv::RNG rng(seed);
  cv::Mat coarse(size.height / coarseness + 2, size.width / coarseness + 2, CV_8UC3);
  rng.fill(coarse, cv::RNG::UNIFORM, low, high);
  cv::Mat out;
  cv::resize(coarse, out, size, 0, 0, cv::INTER_CUBIC);
  cv::Mat fine(size, CV_8UC3);
  rng.fill(fine, cv::RNG::UNIFORM, 0, 25);
  return out + fine;
}

struct Object {
  syn::Profile profile = syn::cup_profile(220, 70, 50);
  cv::Mat surface;  // texture in the object's frame: column = offset from the axis + kHalf, row = along + kHalf
  static constexpr int kHalf = 200;
  explicit Object(uint64_t seed) : surface(texture({2 * kHalf + 1, 2 * kHalf + 1}, seed, 150, 230, 6)) {
    // Stripes across the body: the interior changes when the object moves.
    for (int y = 0; y < surface.rows; y += 24)
      cv::rectangle(surface, {0, y}, {surface.cols, y + 6}, cv::Scalar(60, 90, 200), cv::FILLED);
  }
};

// The object's coverage (0-255, anti-aliased) with its axis on `line`, centred `along` px down it.
cv::Mat coverage(const Object& object, const sym::Line& line, double along, cv::Size size) {
  cv::Mat alpha(size, CV_8U, cv::Scalar(0));
  syn::draw_shape(alpha, object.profile, line.r, line.theta, along, cv::Scalar(255));
  return alpha;
}

// Draws the textured object over `image`, its surface carried along with its axis.
void draw_object(cv::Mat& image, const Object& object, const sym::Line& line, double along) {
  const cv::Point2d centre(0.5 * (image.cols - 1), 0.5 * (image.rows - 1));
  const cv::Point2d n(std::cos(line.theta), std::sin(line.theta)), d(-std::sin(line.theta), std::cos(line.theta));
  // image point -> surface: column = (p - c).n - R + kHalf, row = (p - c).d - along + kHalf
  const cv::Matx23d image_to_surface(n.x, n.y, -centre.dot(n) - line.r + Object::kHalf, d.x, d.y,
                                     -centre.dot(d) - along + Object::kHalf);
  cv::Mat surface;
  cv::warpAffine(object.surface, surface, image_to_surface, image.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  const cv::Mat alpha = coverage(object, line, along, image.size());
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const double a = alpha.at<uint8_t>(y, x) / 255.0;
      if (a <= 0) continue;
      cv::Vec3b& p = image.at<cv::Vec3b>(y, x);
      const cv::Vec3b s = surface.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) p[c] = cv::saturate_cast<uint8_t>((1 - a) * p[c] + a * s[c]);
    }
}

cv::Mat truth_mask(const Object& object, const sym::Line& line, double along, cv::Size size) {
  cv::Mat mask;
  cv::threshold(coverage(object, line, along, size), mask, 127, 255, cv::THRESH_BINARY);
  return mask;
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero(a & b), uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 0;
}

void add_noise(cv::Mat& image, uint64_t seed, double sigma) {
  cv::Mat noise(image.size(), CV_16SC3);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0, sigma);
  cv::Mat wide;
  image.convertTo(wide, CV_16SC3);
  wide += noise;
  wide.convertTo(image, CV_8UC3);
}

struct Nudge {
  cv::Mat before, after, truth_after, truth_before;
  sym::Line line_before, line_after;
};

// A cup on a textured background, its axis moved from `line_before` to `line_after`.
Nudge make_nudge(cv::Size size, const sym::Line& line_before, const sym::Line& line_after, double along = 40,
                 double noise_sigma = 2) {
  const Object object(7);
  const cv::Mat background = texture(size, 11, 40, 120, 12);
  Nudge out;
  out.line_before = line_before;
  out.line_after = line_after;
  out.before = background.clone();
  out.after = background.clone();
  draw_object(out.before, object, line_before, along);
  draw_object(out.after, object, line_after, along);
  add_noise(out.before, 21, noise_sigma);
  add_noise(out.after, 22, noise_sigma);
  out.truth_after = truth_mask(object, line_after, along, size);
  out.truth_before = truth_mask(object, line_before, along, size);
  return out;
}

const cv::Size kSize(640, 480);

}  // namespace

TEST(MotionSegmentation, SidewaysNudgeGivesTheObjectAtItsAfterPosition) {
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-10, 0));
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_NEAR(result.shift, 20, 1e-9);
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
  // At the after position, not the before one.
  EXPECT_GT(iou(result.mask, nudge.truth_after), iou(result.mask, nudge.truth_before) + 0.1);
  EXPECT_EQ(result.area, cv::countNonZero(result.mask));
  // The cut-out is the after image inside the mask and black outside.
  cv::Mat expected = cv::Mat::zeros(kSize, CV_8UC3);
  nudge.after.copyTo(expected, result.mask);
  EXPECT_EQ(cv::norm(cut_out(nudge.after, result.mask), expected, cv::NORM_INF), 0);
}

TEST(MotionSegmentation, NudgeTowardsNegativeRAndGreyImages) {
  const Nudge nudge = make_nudge(kSize, make_line(40, 0), make_line(15, 0));
  cv::Mat before_grey, after_grey;
  cv::cvtColor(nudge.before, before_grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(nudge.after, after_grey, cv::COLOR_BGR2GRAY);
  const MotionSegmentation result = segment_by_motion(before_grey, after_grey, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_NEAR(result.shift, -25, 1e-9);
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
  EXPECT_EQ(cut_out(after_grey, result.mask).type(), CV_8U);
}

TEST(MotionSegmentation, TiltedLine) {
  const Nudge nudge = make_nudge(kSize, make_line(-20, 15 * kDeg), make_line(5, 15 * kDeg));
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
}

TEST(MotionSegmentation, ObjectTurnsALittleAsWellAsMoving) {
  const Nudge nudge = make_nudge(kSize, make_line(-30, -2 * kDeg), make_line(-8, 1 * kDeg));
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_NEAR(result.rotation, 3 * kDeg, 1e-9);
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
}

TEST(MotionSegmentation, LineGivenWithTheOppositeNormal) {
  // (R, theta) and (-R, theta - 180 deg) are one line: near-horizontal axes wrap across +-90 deg.
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-10, 0));
  const sym::Line flipped_before = make_line(30, M_PI);
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, flipped_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_NEAR(result.shift, 20, 1e-9);
  EXPECT_NEAR(result.rotation, 0, 1e-9);
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
}

TEST(MotionSegmentation, SmallShiftStillSegments) {
  // The thesis' white cup moved only a little (fig. 6.8(b)).
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-24, 0));
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.85);
}

TEST(MotionSegmentation, NoiseAndLightingFlicker) {
  Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-10, 0), 40, 4);
  nudge.after += cv::Scalar(9, 9, 9);  // the lights brighten between the two images
  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
}

TEST(MotionSegmentation, NoMotionGivesAnEmptyMaskAndSaysSo) {
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-30, 0), 40, 3);
  MotionStages stages;
  const MotionSegmentation result =
      segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after, {}, &stages);
  EXPECT_FALSE(result.found);
  EXPECT_NE(result.reason.find("no symmetric motion"), std::string::npos) << result.reason;
  EXPECT_EQ(result.area, 0);
  EXPECT_EQ(cv::countNonZero(result.mask), 0);
  EXPECT_EQ(cv::countNonZero(cut_out(nudge.after, result.mask).reshape(1)), 0);
  EXPECT_EQ(cv::countNonZero(stages.cutout.reshape(1)), 0);
  EXPECT_EQ(result.mask.size(), kSize);
}

TEST(MotionSegmentation, ArmAndOtherMotionStayOutOfTheMask) {
  const sym::Line line_before = make_line(-30, 0), line_after = make_line(-10, 0);
  const double along = 40;
  Nudge nudge = make_nudge(kSize, line_before, line_after, along);
  // The effector behind the object (it pushed towards +x) and the arm up to the image's top,
  // in the after image only; the object is in front of it.
  cv::Mat arm(kSize, CV_8U, cv::Scalar(0));
  const cv::Rect object_box = cv::boundingRect(nudge.truth_after);
  const int effector_right = object_box.x + 30, effector_left = object_box.x - 45;
  const int effector_top = object_box.y + object_box.height / 2;
  cv::rectangle(arm, cv::Rect(effector_left, effector_top, effector_right - effector_left, 50), 255, cv::FILLED);
  cv::rectangle(arm, cv::Rect(effector_left, 0, 28, effector_top + 10), 255, cv::FILLED);
  arm &= ~nudge.truth_after;
  nudge.after.setTo(cv::Scalar(35, 35, 35), arm);
  // Another object moves far from the line: a box in the top right corner slides sideways.
  cv::rectangle(nudge.before, cv::Rect(520, 30, 60, 60), cv::Scalar(240, 240, 240), cv::FILLED);
  cv::rectangle(nudge.after, cv::Rect(535, 30, 60, 60), cv::Scalar(240, 240, 240), cv::FILLED);

  const MotionSegmentation result = segment_by_motion(nudge.before, nudge.after, line_before, line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
  EXPECT_LE(cv::countNonZero(result.mask & arm), 0.02 * cv::countNonZero(arm));
  EXPECT_EQ(cv::countNonZero(result.mask(cv::Rect(500, 0, 140, 120))), 0);
}

namespace {

struct MugNudge {
  cv::Mat before, after, body, handle;  // body, handle: true masks at the after position
};

MugNudge make_mug_nudge() {
  const cv::Mat background = texture(kSize, 11, 40, 120, 12);
  const sym::Line line_before = make_line(-30, 0), line_after = make_line(-10, 0);
  MugNudge out;
  out.before = background.clone();
  out.after = background.clone();
  syn::draw_mug(out.before, line_before.r, line_before.theta, 40, 200, 60, cv::Scalar(210, 200, 190));
  syn::draw_mug(out.after, line_after.r, line_after.theta, 40, 200, 60, cv::Scalar(210, 200, 190));
  add_noise(out.before, 31, 2);
  add_noise(out.after, 32, 2);
  cv::Mat mug(kSize, CV_8U, cv::Scalar(0));
  out.body = cv::Mat(kSize, CV_8U, cv::Scalar(0));
  syn::draw_shape(out.body, syn::cup_profile(200, 60, 54), line_after.r, line_after.theta, 40, cv::Scalar(255));
  syn::draw_mug(mug, line_after.r, line_after.theta, 40, 200, 60, cv::Scalar(255));
  cv::threshold(out.body, out.body, 127, 255, cv::THRESH_BINARY);
  cv::threshold(mug, mug, 127, 255, cv::THRESH_BINARY);
  out.handle = mug & ~out.body;
  return out;
}

}  // namespace

TEST(MotionSegmentation, MugHandleMovedWithTheBodyIsIncluded) {
  const MugNudge mug = make_mug_nudge();
  ASSERT_GT(cv::countNonZero(mug.handle), 500);
  const MotionSegmentation result = segment_by_motion(mug.before, mug.after, make_line(-30, 0), make_line(-10, 0));
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(cv::countNonZero(result.mask & mug.handle), 0.6 * cv::countNonZero(mug.handle));
  EXPECT_GE(iou(result.mask, mug.body | mug.handle), 0.9);
}

TEST(MotionSegmentation, WithoutAttachingTheMaskIsSymmetricAndLeavesTheHandleOut) {
  const MugNudge mug = make_mug_nudge();
  MotionParams params;
  params.attach_rigid_parts = false;
  const MotionSegmentation result =
      segment_by_motion(mug.before, mug.after, make_line(-30, 0), make_line(-10, 0), params);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, mug.body), 0.9);
  EXPECT_LE(cv::countNonZero(result.mask & mug.handle), 0.1 * cv::countNonZero(mug.handle));
}

TEST(MotionSegmentation, FullResolutionPair) {
  const cv::Size size(1280, 960);
  const Nudge nudge = make_nudge(size, make_line(-100, 3 * kDeg), make_line(-60, 3 * kDeg), 100);
  MotionSegmenter segmenter;
  const MotionSegmentation result = segmenter.segment(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GE(iou(result.mask, nudge.truth_after), 0.9);
  // The segmenter reuses its scratch images: a second call gives the same mask.
  const MotionSegmentation again = segmenter.segment(nudge.before, nudge.after, nudge.line_before, nudge.line_after);
  EXPECT_EQ(cv::norm(result.mask, again.mask, cv::NORM_INF), 0);
}

TEST(MotionSegmentation, StagesOfFigure67AreSaved) {
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-10, 0));
  MotionStages stages;
  const MotionSegmentation result =
      segment_by_motion(nudge.before, nudge.after, nudge.line_before, nudge.line_after, {}, &stages);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_EQ(stages.difference.size(), kSize);
  EXPECT_EQ(stages.compressed.cols, 2 * MotionParams{}.max_half_width + 1);
  EXPECT_EQ(stages.refined.size(), stages.compressed.size());
  EXPECT_EQ(cv::norm(stages.mask, result.mask, cv::NORM_INF), 0);
  // The line-frame mask is symmetric about the merged line (the middle column).
  cv::Mat mirrored;
  cv::flip(stages.line_frame_mask, mirrored, 1);
  EXPECT_EQ(cv::norm(mirrored, stages.line_frame_mask, cv::NORM_INF), 0);
  EXPECT_GT(cv::countNonZero(stages.line_frame_mask), 0);

  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / ("motion_stages_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  stages.save(dir.string());
  for (const char* name : {"a_before.png", "b_after.png", "c_difference.png", "d_compressed.png", "e_refined.png",
                           "e_mask_line_frame.png", "f_segmentation.png", "mask.png"}) {
    const cv::Mat read = cv::imread((dir / name).string(), cv::IMREAD_UNCHANGED);
    EXPECT_FALSE(read.empty()) << name;
  }
  EXPECT_EQ(cv::imread((dir / "mask.png").string(), cv::IMREAD_GRAYSCALE).size(), kSize);
  std::filesystem::remove_all(dir);
  EXPECT_THROW(MotionStages{}.save(dir.string()), std::logic_error);
}

TEST(MotionSegmentation, TheDifferenceIsEachPixelsLargestChannelChangeAtAnyWidth) {
  // 16 pixels at a time where the CPU has vectors, one at a time at the row's end: widths that
  // are not a multiple of 16, and every byte value, must give what the definition gives.
  for (const int width : {37, 64, 333}) {
    cv::Mat before(50, width, CV_8UC3), after(50, width, CV_8UC3);
    cv::RNG rng(width);
    rng.fill(before, cv::RNG::UNIFORM, 0, 256);
    rng.fill(after, cv::RNG::UNIFORM, 0, 256);
    MotionStages stages;
    segment_by_motion(before, after, make_line(0, 0), make_line(2, 0), {}, &stages);
    std::vector<cv::Mat> channels;
    cv::Mat change;
    cv::absdiff(before, after, change);
    cv::split(change, channels);
    const cv::Mat expected = cv::max(channels[0], cv::max(channels[1], channels[2]));
    ASSERT_EQ(stages.difference.size(), before.size());
    EXPECT_EQ(cv::norm(stages.difference, expected, cv::NORM_INF), 0) << "width " << width;
  }
}

TEST(MotionSegmentation, TheLargestChannelChangeIsNamedForBadImagesAndWorksForFourChannels) {
  cv::Mat a(3, 20, CV_8UC4, cv::Scalar(10, 20, 30, 40)), b(3, 20, CV_8UC4, cv::Scalar(10, 25, 0, 41));
  const cv::Mat change = largest_channel_change(a, b);
  ASSERT_EQ(change.type(), CV_8U);
  EXPECT_EQ(change.at<uint8_t>(1, 7), 30);
  const cv::Mat grey = largest_channel_change(cv::Mat(2, 17, CV_8U, cv::Scalar(9)), cv::Mat(2, 17, CV_8U, cv::Scalar(4)));
  EXPECT_EQ(grey.at<uint8_t>(1, 16), 5);
  EXPECT_THROW(largest_channel_change(a, cv::Mat(3, 21, CV_8UC4)), std::invalid_argument);
  EXPECT_THROW(largest_channel_change(a, cv::Mat(3, 20, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(largest_channel_change(cv::Mat(3, 20, CV_16U), cv::Mat(3, 20, CV_16U)), std::invalid_argument);
}

TEST(MotionSegmentation, TheCutOutIsTheImageWhereTheMaskIsSet) {
  const cv::Mat image(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  cv::Mat mask = cv::Mat::zeros(4, 5, CV_8U);
  mask.at<uint8_t>(1, 2) = 255;
  const cv::Mat cut = cut_out(image, mask);
  EXPECT_EQ(cut.at<cv::Vec3b>(1, 2), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(cv::countNonZero(cut.reshape(1)), 3);
  EXPECT_THROW(cut_out(image, cv::Mat::zeros(3, 5, CV_8U)), std::invalid_argument);
  EXPECT_THROW(cut_out(image, cv::Mat::zeros(4, 5, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(cut_out(cv::Mat(), mask), std::invalid_argument);
}

TEST(MotionSegmentation, BadInputsAreNamed) {
  const cv::Mat image(480, 640, CV_8UC3, cv::Scalar(100, 100, 100));
  const sym::Line line = make_line(0, 0);
  const auto message = [&](const cv::Mat& before, const cv::Mat& after, const sym::Line& lb, const sym::Line& la) {
    try {
      segment_by_motion(before, after, lb, la);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message(cv::Mat(), image, line, line).find("before image is empty"), std::string::npos);
  EXPECT_NE(message(image, cv::Mat(), line, line).find("after image is empty"), std::string::npos);
  EXPECT_NE(message(image, cv::Mat(240, 320, CV_8UC3), line, line).find("320x240"), std::string::npos);
  EXPECT_NE(message(image, cv::Mat(480, 640, CV_8U), line, line).find("after image"), std::string::npos);
  EXPECT_NE(message(cv::Mat(480, 640, CV_32F), cv::Mat(480, 640, CV_32F), line, line).find("8-bit"), std::string::npos);
  EXPECT_NE(message(image, image, make_line(400, 0), line).find("line_before"), std::string::npos);
  EXPECT_NE(message(image, image, line, make_line(-330, 0)).find("line_after"), std::string::npos);
  EXPECT_NE(message(image, image, line, make_line(NAN, 0)).find("line_after"), std::string::npos);
  // A vertical line 300 px right of the centre still crosses a 640 px wide image.
  EXPECT_EQ(message(image, image, make_line(300, 0), make_line(300, 0)), "no exception");

  MotionParams params;
  params.threshold = 0;
  EXPECT_THROW(MotionSegmenter{params}, std::invalid_argument);
  params = {};
  params.max_half_width = 0;
  EXPECT_THROW(MotionSegmenter{params}, std::invalid_argument);
  params = {};
  params.min_vertical_run = 0;
  EXPECT_THROW(validate(params), std::invalid_argument);
}

TEST(MotionSegmentation, LinesTooDifferentAreReportedNotSegmented) {
  const Nudge nudge = make_nudge(kSize, make_line(-30, 0), make_line(-10, 0));
  const MotionSegmentation result =
      segment_by_motion(nudge.before, nudge.after, nudge.line_before, make_line(-10, 35 * kDeg));
  EXPECT_FALSE(result.found);
  EXPECT_NE(result.reason.find("max_rotation_deg"), std::string::npos) << result.reason;
  EXPECT_EQ(cv::countNonZero(result.mask), 0);
}

// ---- Exact cases: flat grey rectangles, no noise, no blur, no noise floor: the answer is known
// to the pixel.

namespace {

MotionParams exact_params() {
  MotionParams p;
  p.blur_sigma = 0;
  p.subtract_noise_floor = false;
  p.attach_rigid_parts = false;
  return p;
}

// Grey background 100; rectangles (rows first..last, half-width w about the line) of grey `value`,
// moved sideways from x = 300 to x = 320.
struct Rect {
  int first, last, half_width;
};
struct ExactNudge {
  cv::Mat before, after, truth;
};
ExactNudge exact_nudge(const std::vector<Rect>& rects, int value, int truth_index = 0) {
  ExactNudge n;
  n.before = cv::Mat(kSize, CV_8UC1, cv::Scalar(100));
  n.after = n.before.clone();
  n.truth = cv::Mat::zeros(kSize, CV_8UC1);
  for (size_t i = 0; i < rects.size(); ++i) {
    const Rect& r = rects[i];
    n.before(cv::Range(r.first, r.last + 1), cv::Range(300 - r.half_width, 300 + r.half_width + 1)).setTo(value);
    n.after(cv::Range(r.first, r.last + 1), cv::Range(320 - r.half_width, 320 + r.half_width + 1)).setTo(value);
    if (static_cast<int>(i) == truth_index)
      n.truth(cv::Range(r.first, r.last + 1), cv::Range(320 - r.half_width, 320 + r.half_width + 1)).setTo(255);
  }
  return n;
}

const sym::Line kExactBefore = make_line(300 - 319.5, 0), kExactAfter = make_line(320 - 319.5, 0);

}  // namespace

TEST(MotionSegmentation, ExactRectangleGivesItsOwnMask) {
  const ExactNudge n = exact_nudge({{150, 300, 40}}, 160);
  const MotionSegmentation result =
      MotionSegmenter(exact_params()).segment(n.before, n.after, kExactBefore, kExactAfter);
  ASSERT_TRUE(result.found) << result.reason;
  // Every pixel of the rectangle, and nothing more than one pixel beyond it (the filled staircase
  // polygon's edges are inclusive: one column and one row more than the truth).
  EXPECT_EQ(cv::countNonZero(n.truth & ~result.mask), 0) << "rectangle pixels left out";
  cv::Mat near_truth;
  cv::dilate(n.truth, near_truth, cv::Mat::ones(3, 3, CV_8U));
  EXPECT_EQ(cv::countNonZero(result.mask & ~near_truth), 0) << "mask pixels more than 1 px off the rectangle";
  EXPECT_LE(result.area, (81 + 1) * (151 + 1));
}

TEST(MotionSegmentation, ChangeOfExactlyTheThresholdCounts) {
  // The difference is 15 grey levels = the threshold: segmented (>= threshold); 14: nothing.
  const MotionParams params = exact_params();
  ASSERT_EQ(params.threshold, 15);
  ExactNudge n = exact_nudge({{150, 300, 40}}, 115);
  EXPECT_TRUE(MotionSegmenter(params).segment(n.before, n.after, kExactBefore, kExactAfter).found);
  n = exact_nudge({{150, 300, 40}}, 114);
  EXPECT_FALSE(MotionSegmenter(params).segment(n.before, n.after, kExactBefore, kExactAfter).found);
}

TEST(MotionSegmentation, TheLargestAreaAlongTheLineIsTheObjectNotTheLongestRun) {
  // A wide short rectangle (61 rows x 81 px) and, far below along the same line, a long thin one
  // (151 rows x 11 px) moved alike: the object is the one with the larger area.
  const ExactNudge n = exact_nudge({{60, 120, 40}, {250, 400, 5}}, 160);
  const MotionSegmentation result =
      MotionSegmenter(exact_params()).segment(n.before, n.after, kExactBefore, kExactAfter);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GT(iou(result.mask, n.truth), 0.95);
}

TEST(MotionSegmentation, ChangeOnlyInTheThirdColourChannelIsSeen) {
  // The same rectangle in colour, different from the background only in channel 2 (red).
  const ExactNudge grey = exact_nudge({{150, 300, 40}}, 160);
  cv::Mat before, after;
  cv::Mat flat(kSize, CV_8UC1, cv::Scalar(100));
  cv::merge(std::vector<cv::Mat>{flat, flat, grey.before}, before);
  cv::merge(std::vector<cv::Mat>{flat, flat, grey.after}, after);
  const MotionSegmentation result =
      MotionSegmenter(exact_params()).segment(before, after, kExactBefore, kExactAfter);
  ASSERT_TRUE(result.found) << result.reason;
  EXPECT_GT(iou(result.mask, grey.truth), 0.95);
}

namespace {

sym::Line line_at(double r, double theta_deg) {
  sym::Line line;
  line.r = r;
  line.theta = theta_deg * M_PI / 180.0;
  return line;
}

}  // namespace

TEST(MirrorAgreement, AnObjectsMaskIsItsOwnMirrorImageAboutItsLine) {
  cv::Mat mask = cv::Mat::zeros(480, 640, CV_8U);
  // A cup-like outline about x = 400, R = 80.5 from the image centre (x = 319.5), theta = 0.
  cv::ellipse(mask, cv::Point(400, 240), cv::Size(60, 100), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  EXPECT_GT(mirror_agreement(mask, line_at(80.5, 0)), 0.95);
  EXPECT_LT(mirror_agreement(mask, line_at(40.5, 0)), 0.6) << "40 px off its axis";
  // The same about a tilted line: rotate the mask with it.
  cv::Mat tilted;
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(319.5f, 239.5f), -10.0, 1.0);
  cv::warpAffine(mask, tilted, turn, mask.size(), cv::INTER_NEAREST);
  EXPECT_GT(mirror_agreement(tilted, line_at(80.5, 10)), 0.9);
  // A piece of one side (a hook, a neighbour's edge) is not.
  cv::Mat piece = cv::Mat::zeros(480, 640, CV_8U);
  cv::rectangle(piece, cv::Rect(400, 150, 60, 40), cv::Scalar(255), cv::FILLED);
  cv::rectangle(piece, cv::Rect(440, 150, 20, 150), cv::Scalar(255), cv::FILLED);
  EXPECT_LT(mirror_agreement(piece, line_at(80.5, 0)), 0.2);
}

// The check reads only the mask's box and its mirror image's: the same agreement as over the
// whole image (the reflection of every pixel, grown by one, and the union counted everywhere),
// for masks near the borders, lines at any angle and mirror images partly off the image.
TEST(MirrorAgreement, TheBoxesAloneAgreeWithTheWholeImage) {
  const auto whole_image = [](const cv::Mat& mask, const sym::Line& line) {
    const cv::Mat object = mask != 0;
    cv::Mat mirrored = mirror_image(object, line);
    cv::dilate(mirrored, mirrored, cv::Mat::ones(3, 3, CV_8U));
    const int either = cv::countNonZero(object | mirrored);
    return either > 0 ? static_cast<double>(cv::countNonZero(object & mirrored)) / either : 0.0;
  };
  cv::RNG rng(20261203);
  int compared = 0, agreeing = 0;
  for (int trial = 0; trial < 200; ++trial) {
    cv::Mat mask = cv::Mat::zeros(240 + rng.uniform(0, 80), 320 + rng.uniform(0, 80), CV_8U);
    const cv::Point centre(rng.uniform(-20, mask.cols + 20), rng.uniform(-20, mask.rows + 20));
    cv::ellipse(mask, centre, cv::Size(rng.uniform(2, 60), rng.uniform(2, 90)), rng.uniform(0, 180), 0, 360,
                cv::Scalar(rng.uniform(1, 256)), cv::FILLED);
    if (rng.uniform(0, 2)) cv::rectangle(mask, cv::Rect(rng.uniform(0, mask.cols), rng.uniform(0, mask.rows), 15, 40), cv::Scalar(255), cv::FILLED);
    const sym::Line line = line_at(rng.uniform(-200.0, 200.0), rng.uniform(-90.0, 90.0));
    const double expected = whole_image(mask, line);
    const double got = mirror_agreement(mask, line);
    ++compared;
    agreeing += expected > 0.1;
    EXPECT_NEAR(got, expected, 0.005) << "trial " << trial;
  }
  // Lines through the mask as well as beside it: ones about their own axis for the agreement's sake.
  for (int trial = 0; trial < 50; ++trial) {
    cv::Mat mask = cv::Mat::zeros(480, 640, CV_8U);
    const double theta = rng.uniform(-30.0, 30.0);
    cv::ellipse(mask, cv::Point2f(319.5f + 100 * std::cos(theta * M_PI / 180), 239.5f + 100 * std::sin(theta * M_PI / 180)),
                cv::Size(rng.uniform(10, 60), rng.uniform(20, 150)), theta, 0, 360, cv::Scalar(255), cv::FILLED);
    const sym::Line line = line_at(100 + rng.uniform(-3.0, 3.0), theta);
    const double expected = whole_image(mask, line);
    ++compared;
    agreeing += expected > 0.1;
    EXPECT_NEAR(mirror_agreement(mask, line), expected, 0.005) << "symmetric trial " << trial;
  }
  EXPECT_GE(agreeing, 50) << "of " << compared << ": the comparison must include masks that do agree";
}

TEST(MirrorAgreement, BadMasksAreNamed) {
  EXPECT_EQ(mirror_agreement(cv::Mat::zeros(10, 10, CV_8U), line_at(0, 0)), 0.0);
  EXPECT_THROW(mirror_agreement(cv::Mat(), line_at(0, 0)), std::invalid_argument);
  EXPECT_THROW(mirror_agreement(cv::Mat::zeros(10, 10, CV_8UC3), line_at(0, 0)), std::invalid_argument);
}

// A mask cut about the right line runs along the object's outline on both sides; one cut about a
// line through the object's left part (symmetric about that line, as the filling makes it) ends
// inside the object on its right, where the image has no edge.
TEST(SideEdgeSupport, AMasksSidesFollowTheObjectsOutlineOnlyWhenItIsTheObject) {
  cv::Mat image(480, 640, CV_8UC3, cv::Scalar(150, 170, 190));  // a plain table
  cv::rectangle(image, cv::Rect(340, 120, 121, 240), cv::Scalar(40, 40, 200), cv::FILLED);  // a red cup, x 340..460
  cv::Mat whole = cv::Mat::zeros(image.size(), CV_8U);
  whole(cv::Rect(340, 120, 121, 240)).setTo(255);
  EXPECT_GT(side_edge_support(whole, image), 0.95);
  // About x = 370 instead of the cup's 400: from its left edge to 60 px inside it.
  cv::Mat half = cv::Mat::zeros(image.size(), CV_8U);
  half(cv::Rect(340, 120, 61, 240)).setTo(255);
  EXPECT_LT(side_edge_support(half, image), 0.1);
  // Spilling 30 px past both sides onto the plain table: no edge on either side.
  cv::Mat spilled = cv::Mat::zeros(image.size(), CV_8U);
  spilled(cv::Rect(310, 120, 181, 240)).setTo(255);
  EXPECT_LT(side_edge_support(spilled, image), 0.1);
  // An outline between two colours of one brightness is an edge too; a grey image works alike.
  cv::Mat isoluminant(480, 640, CV_8UC3, cv::Scalar(0, 128, 0));
  cv::rectangle(isoluminant, cv::Rect(340, 120, 121, 240), cv::Scalar(0, 0, 255), cv::FILLED);
  cv::Mat luminance;
  cv::cvtColor(isoluminant, luminance, cv::COLOR_BGR2GRAY);
  ASSERT_LT(std::abs(luminance.at<uint8_t>(10, 10) - luminance.at<uint8_t>(240, 400)), 3) << "the two colours are one grey";
  EXPECT_GT(side_edge_support(whole, isoluminant), 0.95);
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  EXPECT_GT(side_edge_support(whole, grey), 0.95);
  EXPECT_LT(side_edge_support(half, grey), 0.1);
}

TEST(SideEdgeSupport, BadInputsAreNamed) {
  const cv::Mat image(48, 64, CV_8UC3, cv::Scalar(0));
  EXPECT_EQ(side_edge_support(cv::Mat::zeros(48, 64, CV_8U), image), 0.0);
  EXPECT_THROW(side_edge_support(cv::Mat(), image), std::invalid_argument);
  EXPECT_THROW(side_edge_support(cv::Mat::zeros(48, 64, CV_8UC3), image), std::invalid_argument);
  EXPECT_THROW(side_edge_support(cv::Mat::zeros(48, 64, CV_8U), cv::Mat(48, 65, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(side_edge_support(cv::Mat::zeros(48, 64, CV_8U), cv::Mat(48, 64, CV_32F)), std::invalid_argument);
}

TEST(KeepNearLine, MotionBeyondTheWidestHalfWidthIsCleared) {
  // An object about x = 400 (R = 80.5, theta = 0) 120 px wide, and a neighbour that moved with it
  // joined to its right side (x 460..560).
  cv::Mat mask = cv::Mat::zeros(480, 640, CV_8U);
  cv::rectangle(mask, cv::Rect(340, 100, 121, 200), cv::Scalar(255), cv::FILLED);
  cv::rectangle(mask, cv::Rect(461, 150, 100, 150), cv::Scalar(255), cv::FILLED);
  const int neighbour = 100 * 150;
  cv::Mat kept = mask.clone();
  EXPECT_EQ(keep_near_line(kept, line_at(80.5, 0), 60.5), neighbour);
  EXPECT_EQ(cv::countNonZero(kept), 121 * 200) << "the object itself is kept whole";
  EXPECT_EQ(cv::countNonZero(kept(cv::Rect(461, 0, 179, 480))), 0);
  // Wide enough for both: nothing cleared.
  cv::Mat wide = mask.clone();
  EXPECT_EQ(keep_near_line(wide, line_at(80.5, 0), 200), 0);
  // About a tilted line the band turns with it: a column of pixels along the line is kept, the
  // same column 40 px to its side is not.
  cv::Mat tilted = cv::Mat::zeros(480, 640, CV_8U);
  const sym::Line line = line_at(0, 20);  // through the centre, normal at 20 deg
  for (int y = 0; y < 480; ++y) {
    const double x_on_line = 319.5 - (y - 239.5) * std::tan(20 * M_PI / 180);
    for (int x : {static_cast<int>(std::lround(x_on_line)), static_cast<int>(std::lround(x_on_line + 40 / std::cos(20 * M_PI / 180)))})
      if (x >= 0 && x < 640) tilted.at<uint8_t>(y, x) = 255;
  }
  const int before = cv::countNonZero(tilted);
  const int cleared = keep_near_line(tilted, line, 20);
  EXPECT_NEAR(cleared, before / 2, 2);
}

TEST(KeepNearLine, BadMasksAreNamed) {
  cv::Mat colour = cv::Mat::zeros(10, 10, CV_8UC3), empty, grey = cv::Mat::zeros(10, 10, CV_8U);
  EXPECT_THROW(keep_near_line(colour, line_at(0, 0), 5), std::invalid_argument);
  EXPECT_THROW(keep_near_line(empty, line_at(0, 0), 5), std::invalid_argument);
  EXPECT_THROW(keep_near_line(grey, line_at(0, 0), -1), std::invalid_argument);
}
