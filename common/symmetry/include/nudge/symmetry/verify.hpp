#pragma once
// Verification of detected symmetry lines on busy images (issue 14). The accumulator only counts
// edge pairs; on a busy table its peaks are objects, but also lines between two neighbouring
// objects (one edge of each) and lines in the texture of the table or the wall. What the pairs of
// a peak look like tells them apart:
//  - local support: an object's pairs form one compact band along its axis (its outline), a
//    texture line's pairs are scattered along the line;
//  - appearance: the two sides of an object mirror each other in colour just inside its outline,
//    while the inside of a pair between two objects is the gap between them, and whatever the
//    table or wall shows there is rarely mirror-symmetric about the gap's middle.
// verify_lines() scores the detector's lines by both and keeps the best.
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry {

// Defaults: chosen on the development family of busy tables (docs/clutter.md).
struct VerifyParams {
  int keep = 8;                  // lines returned, best score first
  double band_gap_px = 8;        // pairs further apart along the line start a new band
  // The support segment (Line::seg1/seg2, which the stereo check compares between the cameras) is
  // the largest band grown across gaps up to this: an object whose outline is broken (a stretch
  // against a background of its own colour, a label) keeps its whole height rather than its
  // largest fragment. At most band_gap_px: the band alone.
  double support_gap_px = 0;
  double colour_tolerance = 90;  // L1 BGR difference (0-765) below which mirrored samples agree
  double min_appearance = 0.0;   // drop lines whose appearance agreement is below this (0-1)
  // score = votes x band share ^ band_weight x appearance ^ appearance_weight
  double band_weight = 0.5;
  double appearance_weight = 1;
  // A line this close to a better one (both in R and in theta) is the same peak again: dropped.
  double suppress_px = 4, suppress_deg = 3;
  // Refit each line to the midpoints of its largest band's pairs (a total-least-squares line),
  // when the fit moves it by at most refine_max_deg: an accumulator peak a bin or two beside an
  // object still collects pairs of that object's outline, and the midpoints of chords between
  // two (near-)parallel sides lie on the true axis whatever the chords' angle. Off: the
  // accumulator's (R, theta) as it is.
  bool refine = false;
  double refine_max_deg = 4;
  int refine_min_pairs = 8;  // fewer pairs in the band: too few to fit, the line is kept as it is
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const VerifyParams& params);

struct LineEvidence {
  int pairs = 0;             // edge pairs that voted into the line's peak bin
  double band_share = 0;     // share of them in the largest compact band along the line
  double appearance = 0;     // share of mirrored colour samples inside the pairs that agree
  double score = 0;          // votes x band share ^ band_weight x appearance ^ appearance_weight
};

// Evidence for one line of `detector`'s last detection on `edges` (the edge set of `image`, BGR
// or grey, the size the edges were found at).
LineEvidence line_evidence(const Detector& detector, const EdgeSet& edges, const cv::Mat& image, const Line& line,
                           const VerifyParams& params = {});

// The total-least-squares line through `points` (image pixels) as (R, theta) about the centre of a
// width x height image, theta in (-90, 90] deg; nullopt for fewer than 2 points or no direction.
std::optional<Line> fit_line(const std::vector<cv::Point2d>& points, int width, int height);

// Scores every line and returns the best `params.keep`, best first; each line's support segment
// becomes the extent of its largest band, grown across gaps up to params.support_gap_px (with params.refine the line is first refitted to it). Throws std::invalid_argument if image and edges differ in size.
std::vector<Line> verify_lines(const Detector& detector, const EdgeSet& edges, const cv::Mat& image,
                               const std::vector<Line>& lines, const VerifyParams& params = {},
                               std::vector<LineEvidence>* evidence = nullptr);

}  // namespace nudge::symmetry
