#pragma once
// A symmetry line in an image, and how far apart two lines are.
//
// Conventions (the project's, docs/architecture.md): a line is (R, theta) about the image centre ((w-1)/2, (h-1)/2);
// (cos theta, sin theta) is its normal, so theta = 0 is a vertical line; theta in (-90, 90] deg.
// (R, theta) and (-R, theta + 180 deg) are the same line, which is why differences must wrap.
#include <opencv2/core/types.hpp>

#include <vector>

namespace nudge::symmetry {

struct Line {
  double r = 0;          // px
  double theta = 0;      // radians
  double votes = 0;      // accumulator value at the (discrete) peak
  double skew = 0;       // radians; 0 for bilateral symmetry
  cv::Point2d end1, end2;// where the line meets the image border
  cv::Point2d seg1, seg2;// extent along the line covered by the voting edge pairs
  int r_bin = 0, theta_bin = 0, skew_index = 0;  // the discrete peak
};

// Where the line meets the border of a w x h image (the point of the line nearest the image,
// twice, when it misses the image).
void border_endpoints(double r, double theta, int width, int height, cv::Point2d* p1, cv::Point2d* p2);

// `line`, detected in the part `region` of a `whole` image, in the whole image's coordinates: R about
// the whole image's centre, end1/end2 on its border, seg1/seg2 shifted. The discrete peak's bins
// stay the region's.
Line line_from_region(const Line& line, const cv::Rect& region, const cv::Size& whole);

// line - reference, in (R px, theta rad), with the line taken in whichever of its forms
// (R + 0, theta + k 180 deg, R negated for odd k) is nearest the reference in theta: theta in
// (-90, 90] deg, so lines either side of the +-90 deg wrap come out a few degrees apart.
struct LineDifference {
  double r = 0;      // px
  double theta = 0;  // radians, (-pi/2, pi/2]
};
LineDifference line_difference(double r, double theta, double reference_r, double reference_theta);
inline LineDifference line_difference(const Line& line, const Line& reference) {
  return line_difference(line.r, line.theta, reference.r, reference.theta);
}

// `lines` (strongest first) reordered so that each place in the image is offered once before any
// place is offered twice: a line lying within `min_px` of a line already taken, along the stretch
// where their support segments overlap, waits, in its order, behind every line that does not.
// Where lines are capped (the survey's few per image), an object's second line (a handle's, a
// shading's) or a line hugging it then no longer takes the place of a weaker object's line
// elsewhere. Lines beside each other but at different heights in the image (one object behind
// another) are different places. min_px <= 0: the lines as they are. Throws std::invalid_argument
// when min_px is not finite.
std::vector<Line> one_line_per_place_first(const std::vector<Line>& lines, double min_px);

}  // namespace nudge::symmetry
