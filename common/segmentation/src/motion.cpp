// Object segmentation by motion (Li 2008, sec. 6.4): see motion.hpp for the steps.
#include "nudge/segmentation/motion.hpp"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "line_frame.hpp"

namespace nudge::segmentation {
namespace {

using detail::LineFrame;

std::string describe(const symmetry::Line& line) {
  std::ostringstream out;
  out << "(R = " << line.r << " px, theta = " << line.theta * 180.0 / M_PI << " deg)";
  return out.str();
}

void check_image(const cv::Mat& image, const char* name) {
  if (image.empty()) throw std::invalid_argument(std::string("motion segmentation: the ") + name + " image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument(std::string("motion segmentation: the ") + name +
                                " image must be 8-bit with 1 or 3 channels (got type " + cv::typeToString(image.type()) +
                                ")");
}

// The line must meet the image: its distance from the centre at most the farthest corner's
// projection onto its normal.
void check_line(const symmetry::Line& line, const char* name, cv::Size size) {
  if (!std::isfinite(line.r) || !std::isfinite(line.theta))
    throw std::invalid_argument(std::string("motion segmentation: ") + name + " is not finite " + describe(line));
  const double reach = 0.5 * (std::abs(std::cos(line.theta)) * (size.width - 1) +
                              std::abs(std::sin(line.theta)) * (size.height - 1));
  if (std::abs(line.r) > reach) {
    std::ostringstream out;
    out << "motion segmentation: " << name << ' ' << describe(line) << " does not cross the " << size.width << 'x'
        << size.height << " image";
    throw std::invalid_argument(out.str());
  }
}

void check_inputs(const cv::Mat& before, const cv::Mat& after, const symmetry::Line& line_before,
                  const symmetry::Line& line_after) {
  check_image(before, "before");
  check_image(after, "after");
  if (before.size() != after.size()) {
    std::ostringstream out;
    out << "motion segmentation: the before image is " << before.cols << 'x' << before.rows << ", the after image "
        << after.cols << 'x' << after.rows;
    throw std::invalid_argument(out.str());
  }
  if (before.type() != after.type())
    throw std::invalid_argument("motion segmentation: the before image is " + cv::typeToString(before.type()) +
                                ", the after image " + cv::typeToString(after.type()));
  check_line(line_before, "line_before", before.size());
  check_line(line_after, "line_after", after.size());
}

// The same line with its normal on the side of `reference`'s normal (theta and theta + 180 deg
// describe one line with opposite normals), so that offsets along both normals compare.
symmetry::Line facing(const symmetry::Line& line, const symmetry::Line& reference) {
  symmetry::Line out = line;
  if (std::cos(line.theta - reference.theta) < 0) {
    out.r = -line.r;
    out.theta = line.theta + (line.theta < reference.theta ? M_PI : -M_PI);
  }
  return out;
}

// |after - before|, the largest change over the channels (a change of hue counts too), in one
// pass: 16 pixels at a time where the CPU has 128-bit vectors, the channels deinterleaved in
// registers (a per-channel absdiff and then a max over the channels read and wrote the band twice).
void channel_max_difference(const cv::Mat& before, const cv::Mat& after, cv::Mat& out) {
  if (before.channels() == 1) {
    cv::absdiff(before, after, out);
    return;
  }
  out.create(before.size(), CV_8U);
  for (int y = 0; y < out.rows; ++y) {
    const uint8_t* b = before.ptr<uint8_t>(y);
    const uint8_t* a = after.ptr<uint8_t>(y);
    uint8_t* row = out.ptr<uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    for (; x + 16 <= out.cols; x += 16) {
      cv::v_uint8x16 b0, b1, b2, a0, a1, a2;
      cv::v_load_deinterleave(b + 3 * x, b0, b1, b2);
      cv::v_load_deinterleave(a + 3 * x, a0, a1, a2);
      cv::v_store(row + x, cv::v_max(cv::v_absdiff(a0, b0), cv::v_max(cv::v_absdiff(a1, b1), cv::v_absdiff(a2, b2))));
    }
#endif
    for (; x < out.cols; ++x)
      row[x] = static_cast<uint8_t>(std::max({std::abs(a[3 * x] - b[3 * x]), std::abs(a[3 * x + 1] - b[3 * x + 1]),
                                              std::abs(a[3 * x + 2] - b[3 * x + 2])}));
  }
}

// +-2.5 sigma is plenty for a blur meant against single-pixel noise (OpenCV would take +-3 sigma).
cv::Size kernel_size(double sigma) {
  const int half = std::max(1, static_cast<int>(std::ceil(2.5 * sigma)));
  return {2 * half + 1, 2 * half + 1};
}

// The part of the image the line-frame image samples: the strips of +-reach px about both lines.
cv::Rect band_around(const LineFrame& a, const LineFrame& b, double reach, int first_row, int last_row, cv::Size size) {
  std::vector<cv::Point2f> corners;
  for (const LineFrame* frame : {&a, &b})
    for (const double u : {-reach, reach})
      for (const double v : {first_row - 1.0, last_row + 1.0}) corners.emplace_back(frame->to_image(u, v));
  return cv::boundingRect(corners) & cv::Rect(cv::Point(0, 0), size);
}

// The median grey level of an 8-bit image (every other row: plenty for a median). Four
// histograms, one per pixel of each group of four: consecutive pixels of one level would
// otherwise wait on each other's increment.
int median_level(const cv::Mat& image) {
  std::array<std::array<uint32_t, 256>, 4> partial{};
  uint64_t total = 0;
  for (int y = 0; y < image.rows; y += 2) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    int x = 0;
    for (; x + 4 <= image.cols; x += 4) {
      ++partial[0][row[x]];
      ++partial[1][row[x + 1]];
      ++partial[2][row[x + 2]];
      ++partial[3][row[x + 3]];
    }
    for (; x < image.cols; ++x) ++partial[0][row[x]];
    total += image.cols;
  }
  uint64_t seen = 0;
  for (int level = 0; level < 256; ++level) {
    seen += partial[0][level] + partial[1][level] + partial[2][level] + partial[3][level];
    if (2 * seen >= total) return level;
  }
  return 255;
}

// Samples `image` in `frame` into columns [x0, x0 + dst.cols) of the line-frame image whose
// column `centre_column` is the line and whose row 0 lies `first_row` px along it.
void sample_in_frame(const cv::Mat& image, const LineFrame& frame, int centre_column, int x0, int first_row,
                     cv::Mat dst) {
  const double u0 = frame.r + x0 - centre_column;
  const cv::Matx23d line_to_image(frame.normal.x, frame.direction.x,
                                  frame.centre.x + u0 * frame.normal.x + first_row * frame.direction.x,
                                  frame.normal.y, frame.direction.y,
                                  frame.centre.y + u0 * frame.normal.y + first_row * frame.direction.y);
  // Nearest neighbour: the blur that follows smooths more than bilinear interpolation would, at
  // half the cost.
  cv::warpAffine(image, dst, line_to_image, dst.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                 cv::Scalar(0));
}

// Symmetric filling (e) of the compressed difference `strength` (`spread`: the same dilated by the
// mirror tolerance), all rows at once. Column c = centre - k pairs with centre + k: a pair is as
// strong as its weaker side, max(min(strength[c - k], spread[c + k]), min(spread[c - k],
// strength[c + k])). Mirroring the images left to right lines up every pair's two sides in one
// column, so the pairs are whole-image minima and maxima (vectorised). Returns each row's
// half-width out to its outermost pair of at least `threshold`, -1 if none. `refined`, if given,
// gets every pixel inside the outermost pair set to the strongest pair at or beyond it (fig. 6.7).
std::vector<int> fill_rows(const cv::Mat& strength, const cv::Mat& spread, int threshold, detail::MotionScratch& scratch,
                           cv::Mat* refined) {
  const int centre = strength.cols / 2;
  cv::flip(strength, scratch.mirrored_blurred, 1);
  cv::flip(spread, scratch.mirrored_dilated, 1);
  cv::Mat& pairs = scratch.pairs;
  cv::min(strength, scratch.mirrored_dilated, scratch.mirrored_dilated);  // in place: element by element
  cv::min(spread, scratch.mirrored_blurred, scratch.mirrored_blurred);
  cv::max(scratch.mirrored_dilated, scratch.mirrored_blurred, pairs);
  // The outermost pair at least `threshold`: the first such column of the row's left half.
  cv::compare(pairs.colRange(0, centre + 1), cv::Scalar(threshold), scratch.above_threshold, cv::CMP_GE);
  std::vector<int> half_width(strength.rows, -1);
  for (int y = 0; y < strength.rows; ++y) {
    const uint8_t* row = scratch.above_threshold.ptr<uint8_t>(y);
    const void* first = std::memchr(row, 255, centre + 1);
    if (first) half_width[y] = centre - static_cast<int>(static_cast<const uint8_t*>(first) - row);
  }
  if (refined) {
    refined->create(strength.size(), CV_8U);
    for (int y = 0; y < strength.rows; ++y) {
      const uint8_t* pair = pairs.ptr<uint8_t>(y);
      uint8_t* out = refined->ptr<uint8_t>(y);
      uint8_t outer = 0;
      for (int k = centre; k >= 0; --k) {
        outer = std::max(outer, pair[centre - k]);
        out[centre - k] = out[centre + k] = outer;
      }
    }
  }
  return half_width;
}

// Morphology along the line on the rows' half-widths (-1 = empty row, also beyond the ends),
// windows of `run` rows. min_then_max = true is an opening (a row keeps the widest half-width
// shared by some run of `run` rows through it), false a closing (gaps shorter than `run` - 1 rows
// take their neighbours' width).
std::vector<int> morph_rows(const std::vector<int>& half_width, int run, bool min_then_max) {
  if (run <= 1) return half_width;
  std::vector<int> padded(half_width.size() + 2 * run, -1);
  std::copy(half_width.begin(), half_width.end(), padded.begin() + run);
  const int rows = static_cast<int>(padded.size());
  const auto first = [&](int a, int b) { return min_then_max ? std::min(a, b) : std::max(a, b); };
  const auto second = [&](int a, int b) { return min_then_max ? std::max(a, b) : std::min(a, b); };
  std::vector<int> windowed(rows - run + 1);
  for (int y = 0; y + run <= rows; ++y) {
    int value = padded[y];
    for (int j = y + 1; j < y + run; ++j) value = first(value, padded[j]);
    windowed[y] = value;
  }
  std::vector<int> out(half_width.size());
  for (int y = run; y < rows - run; ++y) {  // every window through an image row lies in `padded`
    int value = windowed[y - run + 1];
    for (int start = y - run + 2; start <= y; ++start) value = second(value, windowed[start]);
    out[y - run] = value;
  }
  return out;
}

// Keeps the run of consecutive non-empty rows with the largest area (the object; chance motion
// elsewhere along the line forms smaller runs).
void keep_largest_run(std::vector<int>& half_width) {
  const int rows = static_cast<int>(half_width.size());
  long best_area = 0;
  int best_first = 0, best_end = 0;
  for (int y = 0; y < rows;) {
    if (half_width[y] < 0) {
      ++y;
      continue;
    }
    const int first = y;
    long area = 0;
    for (; y < rows && half_width[y] >= 0; ++y) area += 2L * half_width[y] + 1;
    if (area > best_area) best_area = area, best_first = first, best_end = y;
  }
  for (int y = 0; y < rows; ++y)
    if (y < best_first || y >= best_end) half_width[y] = -1;
}

// The mask rows (half-widths about the line, row y at first_row + y along it) as a staircase
// polygon filled into the image.
// Returns the polygon's bounding box within the mask.
cv::Rect fill_mask(const std::vector<int>& half_width, const LineFrame& frame, int first_row, cv::Mat& mask) {
  constexpr int kShift = 4;  // sub-pixel vertices: 1/16 px
  const auto vertex = [&](double u, double v) {
    const cv::Point2d p = frame.to_image(u, v);
    return cv::Point(cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift)));
  };
  std::vector<cv::Point> left, right;
  for (int y = 0; y < static_cast<int>(half_width.size()); ++y) {
    if (half_width[y] < 0) continue;
    const double reach = half_width[y] + 0.5, v = first_row + y;
    left.push_back(vertex(-reach, v - 0.5));
    left.push_back(vertex(-reach, v + 0.5));
    right.push_back(vertex(reach, v - 0.5));
    right.push_back(vertex(reach, v + 0.5));
  }
  if (left.empty()) return {};
  left.insert(left.end(), right.rbegin(), right.rend());
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{left}, cv::Scalar(255), cv::LINE_8, kShift);
  const cv::Rect fixed_point_box = cv::boundingRect(left);
  const cv::Rect box(fixed_point_box.x >> kShift, fixed_point_box.y >> kShift, (fixed_point_box.width >> kShift) + 2,
                     (fixed_point_box.height >> kShift) + 2);
  return box & cv::Rect(0, 0, mask.cols, mask.rows);
}

cv::Mat line_frame_mask(const std::vector<int>& half_width, int columns) {
  cv::Mat mask(static_cast<int>(half_width.size()), columns, CV_8U, cv::Scalar(0));
  const int centre = columns / 2;
  for (int y = 0; y < mask.rows; ++y)
    if (half_width[y] >= 0) mask.row(y).colRange(centre - half_width[y], centre + half_width[y] + 1).setTo(255);
  return mask;
}

void draw_line(cv::Mat& image, const symmetry::Line& line, const cv::Scalar& colour) {
  const LineFrame frame(line, image.cols, image.rows);
  const double reach = image.cols + image.rows;
  const cv::Point2d a = frame.to_image(0, -reach), b = frame.to_image(0, reach);
  cv::line(image, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)), colour, 2, cv::LINE_AA);
}

// The rigid motion between two lines: a point at `from`'s position -> the point with the same
// offset from `to`'s line and distance along it. Input coordinates counted from `origin`, output
// in image coordinates.
cv::Matx23d line_to_line(const LineFrame& to, const LineFrame& from, cv::Point origin) {
  const LineFrame& before = to;
  const LineFrame& after = from;
  const cv::Matx22d rotation(before.normal.x * after.normal.x + before.direction.x * after.direction.x,
                             before.normal.x * after.normal.y + before.direction.x * after.direction.y,
                             before.normal.y * after.normal.x + before.direction.y * after.direction.x,
                             before.normal.y * after.normal.y + before.direction.y * after.direction.y);
  const cv::Vec2d foot_before(before.centre.x + before.r * before.normal.x, before.centre.y + before.r * before.normal.y);
  const cv::Vec2d foot_after(after.centre.x + after.r * after.normal.x, after.centre.y + after.r * after.normal.y);
  const cv::Vec2d offset = foot_before - rotation * foot_after + rotation * cv::Vec2d(origin.x, origin.y);
  return cv::Matx23d(rotation(0, 0), rotation(0, 1), offset[0], rotation(1, 0), rotation(1, 1), offset[1]);
}

template <int kChannels>
int channel_max_change(const uint8_t* a, const uint8_t* b) {
  int change = 0;
  for (int c = 0; c < kChannels; ++c) change = std::max(change, std::abs(int(a[c]) - int(b[c])));
  return change;
}

// The candidate pixels of attach_rigid_parts within `roi` (255 = candidate). One pass: most
// pixels did not change and cost one comparison; the maps are only evaluated for the others.
// `change`: the channels' largest |after - before| over `roi`.
template <int kChannels>
cv::Mat rigid_candidates(const cv::Mat& before, const cv::Mat& after, const cv::Mat& change, const cv::Mat& mask,
                         const cv::Matx23d& to_before, const cv::Matx23d& to_after, int changed_level,
                         int rigid_tolerance, const cv::Rect& roi) {
  cv::Mat candidate(roi.size(), CV_8U, cv::Scalar(0));
  const cv::Rect image(0, 0, after.cols, after.rows);
  for (int y = 0; y < roi.height; ++y) {
    const uint8_t* after_row = after.ptr<uint8_t>(roi.y + y) + kChannels * roi.x;
    const uint8_t* changed = change.ptr<uint8_t>(y);
    uint8_t* out = candidate.ptr<uint8_t>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (changed[x] < changed_level) continue;
      const uint8_t* here = after_row + kChannels * x;
      // Where the symmetric mask was before the move: the object uncovered this pixel.
      const cv::Point back(cvRound(to_after(0, 0) * x + to_after(0, 1) * y + to_after(0, 2)),
                           cvRound(to_after(1, 0) * x + to_after(1, 1) * y + to_after(1, 2)));
      if (image.contains(back) && mask.at<uint8_t>(back)) continue;
      const cv::Point there(cvRound(to_before(0, 0) * x + to_before(0, 1) * y + to_before(0, 2)),
                            cvRound(to_before(1, 0) * x + to_before(1, 1) * y + to_before(1, 2)));
      if (!image.contains(there)) continue;
      if (channel_max_change<kChannels>(here, before.ptr<uint8_t>(there.y) + kChannels * there.x) <= rigid_tolerance)
        out[x] = 255;
    }
  }
  return candidate;
}

// Adds to `mask` the asymmetric parts (a mug's handle) that moved rigidly with the object and
// touch the symmetric mask, within `reach` px of its box. A pixel p at the after position
// belongs to the object if it changed (|after - before| at p), lies outside the object's
// symmetric mask at its before position (there the object uncovered the background: the ghost
// strip behind it), and the after image at p matches the before image at p's before position q
// (p moved back with the lines): the same surface. An arm or a hand that appeared does not match.
// Returns the new box.
cv::Rect attach_rigid_parts(const cv::Mat& before, const cv::Mat& after, const LineFrame& frame_before,
                            const LineFrame& frame_after, int changed_level, int rigid_tolerance, int reach,
                            const cv::Rect& box, cv::Mat& change, cv::Mat& mask) {
  const cv::Rect roi = cv::Rect(box.x - reach, box.y - reach, box.width + 2 * reach, box.height + 2 * reach) &
                       cv::Rect(0, 0, after.cols, after.rows);
  channel_max_difference(before(roi), after(roi), change);
  // After position -> before position, and the symmetric mask's position before the move.
  const cv::Matx23d to_before = line_to_line(frame_before, frame_after, roi.tl());
  const cv::Matx23d to_after = line_to_line(frame_after, frame_before, roi.tl());
  cv::Mat candidate =
      after.channels() == 3
          ? rigid_candidates<3>(before, after, change, mask, to_before, to_after, changed_level, rigid_tolerance, roi)
          : rigid_candidates<1>(before, after, change, mask, to_before, to_after, changed_level, rigid_tolerance, roi);
  // Single pixels matching by chance on textured backgrounds go; parts a few px thick stay.
  cv::morphologyEx(candidate, candidate, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  if (cv::countNonZero(candidate) == 0) return box;  // nothing to attach: skip the labelling
  cv::Mat core = mask(roi);  // a view: writes go to mask
  cv::Mat labels;
  const int count = cv::connectedComponents(candidate | core, labels, 8, CV_32S);
  std::vector<uint8_t> touches(count, 0);
  for (int y = 0; y < roi.height; ++y) {
    const uint8_t* in_core = core.ptr<uint8_t>(y);
    const int* label = labels.ptr<int>(y);
    for (int x = 0; x < roi.width; ++x)
      if (in_core[x]) touches[label[x]] = 1;
  }
  for (int y = 0; y < roi.height; ++y) {
    uint8_t* out = core.ptr<uint8_t>(y);
    const int* label = labels.ptr<int>(y);
    for (int x = 0; x < roi.width; ++x)
      if (label[x] > 0 && touches[label[x]]) out[x] = 255;
  }
  return roi;
}

struct Compressed {
  int first_row = 0;    // row 0 of the line-frame images lies this far along the lines
  int noise_floor = 0;  // grey levels subtracted from the difference
};

// (c) the difference and its noise floor, only where the line-frame image will sample it; (d)
// compression: the leading half (in the direction of motion) sampled beyond the after line, the
// trailing half beyond the before line, the strip between the lines dropped; then the blur.
// Leaves the result in scratch.blurred.
Compressed compress(const cv::Mat& before, const cv::Mat& after, const LineFrame& frame_before,
                    const LineFrame& frame_after, bool leading_is_positive, const MotionParams& params,
                    detail::MotionScratch& scratch) {
  Compressed out;
  int last_row = 0, first_b = 0, last_b = 0;
  detail::row_range(frame_after, after.cols, after.rows, &out.first_row, &last_row);
  detail::row_range(frame_before, before.cols, before.rows, &first_b, &last_b);
  out.first_row = std::min(out.first_row, first_b);
  last_row = std::max(last_row, last_b);
  const int centre = params.max_half_width;

  const cv::Rect band = band_around(frame_after, frame_before, centre + 2, out.first_row, last_row, after.size());
  channel_max_difference(before(band), after(band), scratch.difference);
  out.noise_floor = params.subtract_noise_floor ? median_level(scratch.difference) : 0;
  LineFrame band_after = frame_after, band_before = frame_before;  // the same lines, the band's origin
  band_after.centre -= cv::Point2d(band.tl());
  band_before.centre -= cv::Point2d(band.tl());

  cv::Mat& compressed = scratch.compressed;
  compressed.create(last_row - out.first_row + 1, 2 * centre + 1, CV_8U);
  const int after_x0 = leading_is_positive ? centre : 0;
  const int before_x0 = leading_is_positive ? 0 : centre + 1;
  sample_in_frame(scratch.difference, band_after, centre, after_x0, out.first_row,
                  compressed.colRange(after_x0, after_x0 + centre + 1));
  sample_in_frame(scratch.difference, band_before, centre, before_x0, out.first_row,
                  compressed.colRange(before_x0, before_x0 + centre));
  if (out.noise_floor > 0) cv::subtract(compressed, cv::Scalar(out.noise_floor), compressed);
  if (params.blur_sigma > 0)
    cv::GaussianBlur(compressed, scratch.blurred, kernel_size(params.blur_sigma), params.blur_sigma);
  else
    compressed.copyTo(scratch.blurred);
  return out;
}

// (e) symmetric filling of scratch.blurred (into scratch.refined when `keep_refined`), the
// threshold row by row, and the cleaning along the line: each row's half-width about the merged
// line, -1 = not object.
std::vector<int> symmetric_rows(const MotionParams& params, bool keep_refined, detail::MotionScratch& scratch) {
  const cv::Mat& blurred = scratch.blurred;
  if (params.mirror_tolerance > 0)
    cv::dilate(blurred, scratch.dilated,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * params.mirror_tolerance + 1, 1)));
  else
    blurred.copyTo(scratch.dilated);
  const int threshold = static_cast<int>(std::ceil(params.threshold));
  std::vector<int> half_width =
      fill_rows(blurred, scratch.dilated, threshold, scratch, keep_refined ? &scratch.refined : nullptr);
  half_width = morph_rows(half_width, params.min_vertical_run, true);
  half_width = morph_rows(half_width, params.max_row_gap + 2, false);
  keep_largest_run(half_width);
  return half_width;
}

}  // namespace

void validate(const MotionParams& params) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("MotionParams: " + what); };
  if (!(params.threshold > 0 && params.threshold <= 255)) fail("threshold must be in (0, 255]");
  if (!(params.blur_sigma >= 0 && params.blur_sigma <= 20)) fail("blur_sigma must be in [0, 20] px");
  if (params.max_half_width < 1 || params.max_half_width > 10000) fail("max_half_width must be in [1, 10000] px");
  if (params.mirror_tolerance < 0 || params.mirror_tolerance > 50) fail("mirror_tolerance must be in [0, 50] px");
  if (params.min_vertical_run < 1 || params.min_vertical_run > 1000) fail("min_vertical_run must be in [1, 1000] rows");
  if (params.max_row_gap < 0 || params.max_row_gap > 1000) fail("max_row_gap must be in [0, 1000] rows");
  if (params.min_area < 0) fail("min_area must be >= 0");
  if (!(params.max_rotation_deg >= 0 && params.max_rotation_deg < 90)) fail("max_rotation_deg must be in [0, 90)");
  if (params.attach_reach < 0 || params.attach_reach > 10000) fail("attach_reach must be in [0, 10000] px");
  if (!(params.rigid_tolerance >= 0 && params.rigid_tolerance <= 255)) fail("rigid_tolerance must be in [0, 255]");
}

MotionSegmenter::MotionSegmenter(MotionParams params) : params_(params) { validate(params_); }

MotionSegmentation MotionSegmenter::segment(const cv::Mat& before, const cv::Mat& after,
                                            const symmetry::Line& line_before_in, const symmetry::Line& line_after,
                                            MotionStages* stages) {
  check_inputs(before, after, line_before_in, line_after);
  const symmetry::Line line_before = facing(line_before_in, line_after);
  const LineFrame frame_before(line_before, before.cols, before.rows);
  const LineFrame frame_after(line_after, after.cols, after.rows);

  MotionSegmentation result;
  result.mask = cv::Mat::zeros(after.size(), CV_8U);
  // The motion: where the after line's foot lies relative to the before line.
  result.shift = (frame_after.centre + line_after.r * frame_after.normal - frame_before.centre).dot(frame_before.normal) -
                 line_before.r;
  result.rotation = line_after.theta - line_before.theta;
  if (std::abs(result.rotation) > params_.max_rotation_deg * M_PI / 180.0) {
    std::ostringstream out;
    out << "the lines' orientations differ by " << std::abs(result.rotation) * 180.0 / M_PI << " deg > max_rotation_deg "
        << params_.max_rotation_deg << " (not the same object?): line_before " << describe(line_before_in)
        << ", line_after " << describe(line_after);
    result.reason = out.str();
    return result;
  }

  const Compressed compressed = compress(before, after, frame_before, frame_after, result.shift >= 0, params_, scratch_);
  const std::vector<int> half_width = symmetric_rows(params_, stages != nullptr, scratch_);
  const int threshold = static_cast<int>(std::ceil(params_.threshold));

  // (f) the mask at the after position (plus what moved with it), and the cut-out.
  cv::Rect box = fill_mask(half_width, frame_after, compressed.first_row, result.mask);
  result.area = box.empty() ? 0 : cv::countNonZero(result.mask(box));
  if (result.area < params_.min_area || result.area == 0) {
    std::ostringstream out;
    out << "no symmetric motion about the lines: " << result.area << " px < min_area " << params_.min_area
        << " (shift " << result.shift << " px)";
    result.reason = out.str();
    result.mask.setTo(0);
    result.area = 0;
  } else {
    if (params_.attach_rigid_parts && params_.attach_reach > 0) {
      box = attach_rigid_parts(before, after, frame_before, frame_after, compressed.noise_floor + threshold,
                               static_cast<int>(params_.rigid_tolerance), params_.attach_reach, box, scratch_.difference,
                               result.mask);
      result.area = cv::countNonZero(result.mask(box));
    }
    result.found = true;
    result.bounding_box = cv::boundingRect(result.mask(box)) + box.tl();
  }

  if (stages) {
    stages->before = before.clone();
    stages->after = after.clone();
    channel_max_difference(before, after, stages->difference);  // the whole image
    stages->compressed = scratch_.blurred.clone();
    stages->refined = scratch_.refined.clone();
    stages->line_frame_mask = line_frame_mask(half_width, scratch_.blurred.cols);
    stages->mask = result.mask.clone();
    stages->cutout = cut_out(after, result.mask);
    stages->line_before = line_before_in;
    stages->line_after = line_after;
    stages->first_row = compressed.first_row;
    stages->noise_floor = compressed.noise_floor;
  }
  return result;
}

MotionSegmentation segment_by_motion(const cv::Mat& before, const cv::Mat& after, const symmetry::Line& line_before,
                                     const symmetry::Line& line_after, const MotionParams& params, MotionStages* stages) {
  return MotionSegmenter(params).segment(before, after, line_before, line_after, stages);
}

void MotionStages::save(const std::string& directory) const {
  if (before.empty() || after.empty() || difference.empty() || compressed.empty())
    throw std::logic_error("MotionStages::save: no stages to save (pass stages to segment first)");
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw std::runtime_error("MotionStages::save: cannot create directory " + directory + ": " + error.message());

  cv::Mat difference_lines;
  cv::cvtColor(difference, difference_lines, cv::COLOR_GRAY2BGR);
  draw_line(difference_lines, line_before, cv::Scalar(0, 255, 0));
  draw_line(difference_lines, line_after, cv::Scalar(0, 0, 255));

  const std::vector<std::pair<std::string, const cv::Mat*>> files = {
      {"a_before.png", &before},         {"b_after.png", &after},
      {"c_difference.png", &difference_lines}, {"d_compressed.png", &compressed},
      {"e_refined.png", &refined},       {"e_mask_line_frame.png", &line_frame_mask},
      {"f_segmentation.png", &cutout},   {"mask.png", &mask}};
  for (const auto& [name, image] : files) {
    const std::string path = (std::filesystem::path(directory) / name).string();
    bool written = false;
    try {
      written = !image->empty() && cv::imwrite(path, *image);
    } catch (const cv::Exception& e) {
      throw std::runtime_error("MotionStages::save: cannot write " + path + ": " + e.what());
    }
    if (!written) throw std::runtime_error("MotionStages::save: cannot write " + path);
  }
}

cv::Mat largest_channel_change(const cv::Mat& earlier, const cv::Mat& later) {
  if (earlier.empty() || earlier.size() != later.size() || earlier.type() != later.type() || earlier.depth() != CV_8U)
    throw std::invalid_argument("largest_channel_change: the images must be 8-bit, of one size and type");
  cv::Mat change;
  if (earlier.channels() == 1 || earlier.channels() == 3) {
    channel_max_difference(earlier, later, change);
    return change;
  }
  cv::absdiff(earlier, later, change);
  std::vector<cv::Mat> channels;
  cv::split(change, channels);
  for (size_t c = 1; c < channels.size(); ++c) cv::max(channels[0], channels[c], channels[0]);
  return channels[0];
}

cv::Mat cut_out(const cv::Mat& image, const cv::Mat& mask) {
  if (image.empty() || mask.size() != image.size() || mask.type() != CV_8UC1)
    throw std::invalid_argument("cut_out: the mask must be 8-bit, one channel, the image's size");
  cv::Mat out = cv::Mat::zeros(image.size(), image.type());
  image.copyTo(out, mask);
  return out;
}

namespace {

// The reflection about `line` ((R, theta) about the centre of an image of `size`) in the pixel
// coordinates of `roi`: p' = p - 2 (n . p - n . c - R) n, its own inverse.
cv::Matx23d reflection(const symmetry::Line& line, cv::Size size, const cv::Rect& roi) {
  const double nx = std::cos(line.theta), ny = std::sin(line.theta);
  const double offset = 2.0 * (nx * 0.5 * (size.width - 1) + ny * 0.5 * (size.height - 1) + line.r);
  const cv::Matx22d a(1 - 2 * nx * nx, -2 * nx * ny, -2 * nx * ny, 1 - 2 * ny * ny);
  // Whole image: q = A p + offset n. In the roi's coordinates (p = p' + o): q' = A p' + A o + offset n - o.
  const cv::Vec2d o(roi.x, roi.y);
  const cv::Vec2d t = a * o + offset * cv::Vec2d(nx, ny) - o;
  return cv::Matx23d(a(0, 0), a(0, 1), t[0], a(1, 0), a(1, 1), t[1]);
}

// The smallest rectangle of an image of `size` holding `box` and its reflection about `line`,
// grown by `margin` px.
cv::Rect box_and_its_mirror(const cv::Rect& box, const symmetry::Line& line, cv::Size size, int margin) {
  const cv::Matx23d reflect = reflection(line, size, cv::Rect(0, 0, size.width, size.height));
  double x0 = box.x, y0 = box.y, x1 = box.x + box.width - 1, y1 = box.y + box.height - 1;
  for (const cv::Point2d corner : {cv::Point2d(box.x, box.y), cv::Point2d(box.x + box.width - 1, box.y),
                                   cv::Point2d(box.x, box.y + box.height - 1),
                                   cv::Point2d(box.x + box.width - 1, box.y + box.height - 1)}) {
    const cv::Point2d q(reflect(0, 0) * corner.x + reflect(0, 1) * corner.y + reflect(0, 2),
                        reflect(1, 0) * corner.x + reflect(1, 1) * corner.y + reflect(1, 2));
    x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
  }
  const cv::Rect grown(cv::Point(static_cast<int>(std::floor(x0)) - margin, static_cast<int>(std::floor(y0)) - margin),
                       cv::Point(static_cast<int>(std::ceil(x1)) + margin + 1, static_cast<int>(std::ceil(y1)) + margin + 1));
  return grown & cv::Rect(0, 0, size.width, size.height);
}

}  // namespace

cv::Mat mirror_image(const cv::Mat& image, const symmetry::Line& line) {
  cv::Mat mirrored;
  cv::warpAffine(image, mirrored, reflection(line, image.size(), cv::Rect(0, 0, image.cols, image.rows)), image.size(),
                 cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  return mirrored;
}

double mirror_agreement(const cv::Mat& mask, const symmetry::Line& line) {
  if (mask.empty() || mask.type() != CV_8UC1) throw std::invalid_argument("mirror_agreement: the mask must be 8-bit, one channel");
  // Only the mask's box and its mirror image can hold either: a mask is a few percent of a
  // 1280x960 still, and whole-image passes were most of this check's time.
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return 0.0;
  constexpr int kMargin = 2;  // the one-pixel growth and the nearest-pixel rounding
  const cv::Rect roi = box_and_its_mirror(box, line, mask.size(), kMargin);
  const cv::Mat object = mask(roi) != 0;
  cv::Mat mirrored;
  cv::warpAffine(object, mirrored, reflection(line, mask.size(), roi), roi.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::dilate(mirrored, mirrored, cv::Mat::ones(3, 3, CV_8U));
  const int both = cv::countNonZero(object & mirrored);
  const int either = cv::countNonZero(object | mirrored);
  return either > 0 ? static_cast<double>(both) / either : 0.0;
}

namespace {

// Canny edges of `image` (grey, and each channel of a colour image: an outline between two colours
// of one brightness is an edge too), blurred first.
cv::Mat edges_of(const cv::Mat& image, const SideEdgeParams& params) {
  std::vector<cv::Mat> planes;
  if (image.channels() == 3) {
    cv::split(image, planes);
    cv::Mat grey;
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    planes.push_back(grey);
  } else {
    planes.push_back(image);
  }
  cv::Mat edges = cv::Mat::zeros(image.size(), CV_8UC1);
  for (const cv::Mat& plane : planes) {
    cv::Mat blurred, found;
    if (params.blur_sigma > 0) cv::GaussianBlur(plane, blurred, cv::Size(), params.blur_sigma);
    else blurred = plane;
    cv::Canny(blurred, found, params.canny_low, params.canny_high);
    edges |= found;
  }
  return edges;
}

}  // namespace

double side_edge_support(const cv::Mat& mask, const cv::Mat& image, const SideEdgeParams& params) {
  if (mask.empty() || mask.type() != CV_8UC1) throw std::invalid_argument("side_edge_support: the mask must be 8-bit, one channel");
  if (image.size() != mask.size() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("side_edge_support: the image must be 8-bit grey or BGR, of the mask's size");
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return 0.0;
  // Edges around the box only (the blur and Canny's own window need a margin beyond it).
  const int margin = params.tolerance_px + static_cast<int>(std::ceil(3 * params.blur_sigma)) + 2;
  const cv::Rect roi = cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
                       cv::Rect(cv::Point(), mask.size());
  cv::Mat near_edge;
  const int reach = 2 * params.tolerance_px + 1;
  cv::dilate(edges_of(image(roi), params), near_edge, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(reach, reach)));
  const int first = box.y + static_cast<int>(params.trim * box.height), last = box.y + box.height - static_cast<int>(params.trim * box.height);
  int rows = 0, left_on = 0, right_on = 0;
  for (int y = first; y < last; ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(y);
    int left = -1, right = -1;
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (!row[x]) continue;
      if (left < 0) left = x;
      right = x;
    }
    if (left < 0) continue;
    ++rows;
    left_on += near_edge.at<uint8_t>(y - roi.y, left - roi.x) != 0;
    right_on += near_edge.at<uint8_t>(y - roi.y, right - roi.x) != 0;
  }
  return rows > 0 ? static_cast<double>(std::min(left_on, right_on)) / rows : 0.0;
}

int keep_near_line(cv::Mat& mask, const symmetry::Line& line, double half_width_px) {
  if (mask.empty() || mask.type() != CV_8UC1) throw std::invalid_argument("keep_near_line: the mask must be 8-bit, one channel");
  if (!(half_width_px >= 0)) throw std::invalid_argument("keep_near_line: half_width_px must be >= 0");
  const double cx = (mask.cols - 1) / 2.0, cy = (mask.rows - 1) / 2.0;
  const double c = std::cos(line.theta), s = std::sin(line.theta);
  int cleared = 0;
  for (int y = 0; y < mask.rows; ++y) {
    uint8_t* row = mask.ptr<uint8_t>(y);
    // The signed distance of pixel x from the line is (x - cx) c + (y - cy) s - r: linear in x.
    const double offset = (y - cy) * s - line.r - cx * c;
    for (int x = 0; x < mask.cols; ++x)
      if (row[x] && std::abs(x * c + offset) > half_width_px) row[x] = 0, ++cleared;
  }
  return cleared;
}

}  // namespace nudge::segmentation
