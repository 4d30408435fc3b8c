#pragma once
// The rotation table and quantisation shared by the fast and the reference voting, so that both
// produce bit-identical accumulators. All arithmetic is integer:
//   u2 = 2x - (w-1), v2 = 2y - (h-1)                 (doubled coordinates about the image centre)
//   C = round(cos(theta) 2^14), S = round(sin(theta) 2^14)
//   xq  = round(2 x')  = (u2 C + v2 S + 2^13) >> 14   (rotated x in half pixels)
//   row = round(y')    = (v2 C - u2 S + 2^14) >> 15   (row of Rot, 1 px high)
// A pair (a, b) in one row votes for R = (xq_a + xq_b) / 4 px, binned to the nearest pixel.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry::detail {

constexpr int kFixedShift = 14;
constexpr int kMaxSide = 16384;  // keeps u2*C + v2*S inside int32

struct ThetaTable {
  int32_t c = 0, s = 0;
  double tan_theta = 0;
};

inline ThetaTable theta_table(int bin) {
  const double theta = theta_of_bin_deg(bin) * M_PI / 180.0;
  ThetaTable t;
  t.c = static_cast<int32_t>(std::lround(std::cos(theta) * (1 << kFixedShift)));
  t.s = static_cast<int32_t>(std::lround(std::sin(theta) * (1 << kFixedShift)));
  return t;
}

inline int32_t rotated_xq(int32_t u2, int32_t v2, const ThetaTable& t) {
  return (u2 * t.c + v2 * t.s + (1 << (kFixedShift - 1))) >> kFixedShift;
}
inline int32_t rotated_row(int32_t u2, int32_t v2, const ThetaTable& t) {
  return (v2 * t.c - u2 * t.s + (1 << kFixedShift)) >> (kFixedShift + 1);
}

// Mirror-consistent pairs (Params::mirror_tolerance_deg): the gradient orientations a, b of a pair
// voting for the line of normal angle theta are mirror images about it iff a + b = 2 theta
// (modulo 180 deg). In EdgeSet::orientation units the sum wraps in int16 by itself.
struct MirrorRule {
  bool on = false;
  int16_t target = 0;     // 2 theta, orientation units
  int16_t tolerance = 0;  // orientation units
};

// With polarity the angles are EdgeSet::direction (modulo 360 deg): a + b = 2 theta + 180 deg.
inline MirrorRule mirror_rule(int bin, double tolerance_deg, bool polarity = false) {
  MirrorRule m;
  m.on = tolerance_deg > 0;
  const double two_theta = 2.0 * theta_of_bin_deg(bin) * M_PI / 180.0;
  m.target = polarity ? direction_units(two_theta + M_PI) : orientation_units(two_theta);
  const double units_per_deg = 65536.0 / (polarity ? 360.0 : 180.0);
  m.tolerance = static_cast<int16_t>(std::min(32767.0, std::round(tolerance_deg * units_per_deg)));
  return m;
}

// The per-pixel angles the mirror rule compares: orientations, or directions with polarity.
inline const std::vector<int16_t>& mirror_angles(const EdgeSet& edges, const Params& p) {
  return p.mirror_polarity ? edges.direction : edges.orientation;
}
inline void require_mirror_angles(const EdgeSet& edges, const Params& p) {
  if (p.mirror_tolerance_deg > 0 && mirror_angles(edges, p).size() != edges.points.size())
    throw std::invalid_argument(p.mirror_polarity
                                    ? "symmetry parameter mirror_polarity needs the edge pixels' gradient directions "
                                      "(EdgeSet::direction, EdgeParams::gradients)"
                                    : "symmetry parameter mirror_tolerance needs the edge pixels' orientations "
                                      "(EdgeParams::gradients)");
}

inline int16_t mirror_error(int16_t a, int16_t b, int16_t target) {
  return static_cast<int16_t>(static_cast<uint16_t>(static_cast<uint16_t>(a) + static_cast<uint16_t>(b) -
                                                    static_cast<uint16_t>(target)));
}

inline bool mirror_consistent(int16_t a, int16_t b, const MirrorRule& m) {
  return !m.on || std::abs(static_cast<int>(mirror_error(a, b, m.target))) <= m.tolerance;
}

// Geometry of the accumulator and the pair-distance limits, in the quantised units above.
struct Layout {
  int r_max = 0;        // R bins: -r_max..r_max
  int row_max = 0;      // rows of Rot: -row_max..row_max
  int xq_max = 0;       // |xq| <= xq_max
  int32_t dmin2 = 0;    // minimum |xq_a - xq_b|
  int32_t dmax2 = 0;    // maximum |xq_a - xq_b|
  int32_t sum_offset = 0;  // added to xq_a + xq_b to make it a non-negative index

  // R bin of a pair sum s = xq_a + xq_b: nearest integer to s/4, plus r_max.
  int bin_of_sum(int32_t s) const { return ((s + sum_offset + 2) >> 2) - (sum_offset >> 2) + r_max; }
  int num_r() const { return 2 * r_max + 1; }
};

inline Layout make_layout(int width, int height, const Params& p) {
  Layout l;
  const double half_diag = 0.5 * std::hypot(width, height);
  l.r_max = static_cast<int>(std::ceil(half_diag)) + 1;
  l.row_max = l.r_max;
  l.xq_max = 2 * l.r_max;
  l.dmin2 = static_cast<int32_t>(std::ceil(2.0 * p.dmin - 1e-9));
  if (l.dmin2 < 0) l.dmin2 = 0;
  const bool no_max = !(p.dmax > 0) || std::isinf(p.dmax) || 2.0 * p.dmax >= 4.0 * l.xq_max;
  l.dmax2 = no_max ? 4 * l.xq_max : static_cast<int32_t>(std::floor(2.0 * p.dmax + 1e-9));
  l.sum_offset = 4 * (l.r_max + 2);
  return l;
}

}  // namespace nudge::symmetry::detail
