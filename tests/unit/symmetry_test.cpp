#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <random>

#include "nudge/symmetry/corner_cutting.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/gst.hpp"
#include "nudge/symmetry/line.hpp"
#include "nudge/symmetry/loy_eklundh.hpp"
#include "nudge/symmetry/photo.hpp"
#include "nudge/symmetry/synthetic.hpp"

using namespace nudge::symmetry;
namespace syn = nudge::symmetry::synthetic;

namespace {

constexpr double kDeg = M_PI / 180.0;

// |theta difference| of two lines, degrees in [0, 90] (line.hpp: across the +-90 deg wrap).
double angle_diff_deg(double a, double b) { return std::fabs(line_difference(0.0, a, 0.0, b).theta) / kDeg; }

// |R difference| of a line from (r, theta), allowing for (R, theta) == (-R, theta +- 180).
double r_diff(const Line& l, double r, double theta) { return std::fabs(line_difference(l.r, l.theta, r, theta).r); }

cv::Mat blank(int w = 320, int h = 240, int grey = 220) { return cv::Mat(h, w, CV_8UC1, cv::Scalar(grey)); }

Params synthetic_params() {
  Params p;
  p.dmin = 10;
  p.dmax = 0;  // no limit (thesis: synthetic images)
  return p;
}

void expect_same_accumulator(const Accumulator& a, const Accumulator& b) {
  ASSERT_EQ(a.r_max, b.r_max);
  ASSERT_EQ(a.votes.size(), b.votes.size());
  for (size_t l = 0; l < a.votes.size(); ++l) {
    EXPECT_EQ(cv::countNonZero(a.votes[l] != b.votes[l]), 0) << "layer " << l;
    EXPECT_GT(cv::sum(a.votes[l])[0], 0) << "layer " << l << " has no votes: the comparison proves nothing";
  }
}

}  // namespace

TEST(SymmetryVote, FastEqualsPlainOnScenesAndOptions) {
  // Every option, short and long rows, 16-bit rows (320 x 240) and 32-bit rows (an image too wide
  // for 16-bit coordinates), with and without the mirror rule (grey and colour gradients).
  struct Case {
    double dmin, dmax, tmin, tmax;
    bool once;
    int max_row;
    std::vector<double> skew;
    double mirror = 0;
    bool colour = false;
    int width = 320, height = 240;
  };
  const std::vector<Case> cases = {
      {25, 250, -90, 90, false, 0, {}},  {10, 0, -90, 90, false, 0, {}},  {25, 250, -20, 25, false, 0, {}},
      {25, 250, 70, -70, false, 0, {}},  {5, 60, -90, 90, true, 0, {}},   {25, 250, -90, 90, false, 40, {}},
      {20, 200, -30, 30, false, 0, {-20, 15}}, {0, 30, -90, 90, false, 0, {}},
      {25, 250, -90, 90, false, 0, {}, 15},  {10, 0, -25, 25, false, 0, {}, 5, true},
      {5, 60, -90, 90, true, 0, {}, 30},     {10, 60, -10, 10, false, 0, {}, 20, false, 5600, 40},
      {10, 60, -10, 10, false, 0, {}, 0, false, 5600, 40},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    Params p;
    p.dmin = c.dmin;
    p.dmax = c.dmax;
    p.theta_min_deg = c.tmin;
    p.theta_max_deg = c.tmax;
    p.once_per_row = c.once;
    p.max_row_pixels = c.max_row;
    p.skew_deg = c.skew;
    p.mirror_tolerance_deg = c.mirror;
    const cv::Mat scene = syn::indoor_scene(static_cast<uint32_t>(100 + i), c.width, c.height, 2);
    EdgeParams e{1.0, 30, 90, false};
    e.colour = c.colour;
    e.gradients = c.mirror > 0;
    const EdgeSet edges = detect_edges(scene, e);
    ASSERT_GT(edges.points.size(), 500u);
    ASSERT_EQ(edges.orientation.size(), c.mirror > 0 ? edges.points.size() : 0u);
    Detector fast(p);
    SCOPED_TRACE("case " + std::to_string(i));
    expect_same_accumulator(fast.vote(edges), reference_vote(edges, p));
  }
}

TEST(SymmetryVote, MirrorRuleKeepsMirroredOrientationsAndDropsOthers) {
  // Edge pixels placed mirror-symmetrically about the vertical line x = 100 of a 201 x 201 image.
  // Votes for that axis (R = 0, theta = 0) need the two orientations of a pair to be mirror
  // images about it: a + b = 0 (mod 180 deg).
  EdgeSet edges;
  edges.width = edges.height = 201;
  std::mt19937 rng(5);
  for (int y = 20; y < 180; y += 2) {
    const int dx = std::uniform_int_distribution<int>(15, 80)(rng);
    edges.points.emplace_back(100 - dx, y);
    edges.points.emplace_back(100 + dx, y);
  }
  auto axis_votes = [&](double left_deg, double right_deg, double tolerance) {
    edges.orientation.clear();
    for (size_t i = 0; i < edges.points.size(); ++i)
      edges.orientation.push_back(orientation_units((i % 2 == 0 ? left_deg : right_deg) * kDeg));
    Params p = synthetic_params();
    p.mirror_tolerance_deg = tolerance;
    Detector d(p);
    const Accumulator& acc = d.vote(edges);
    return acc.votes[0].at<int32_t>(89 /* theta 0 */, acc.r_max /* R 0 */);
  };
  const int all = axis_votes(30, 30, 0);
  ASSERT_GE(all, 80);                                // one pair per row of the shape
  EXPECT_EQ(axis_votes(30, -30, 10), all);           // mirrored: every pair still votes
  EXPECT_EQ(axis_votes(30, 150, 10), all);           // mirrored, opposite polarity (mod 180 deg)
  EXPECT_EQ(axis_votes(30, -22, 10), all);           // 8 deg off: inside the tolerance
  EXPECT_EQ(axis_votes(30, -18, 10), 0);             // 12 deg off: outside
  EXPECT_EQ(axis_votes(30, 30, 10), 0);              // parallel, not mirrored
  EXPECT_EQ(axis_votes(30, 30, 90), all);            // a tolerance of 90 deg accepts everything
}

TEST(SymmetryDetect, MirrorRuleRaisesTheAxisAboveClutter) {
  // A bottle among random line-segment clutter: with mirror-consistent pairs the clutter's votes
  // drop far more than the axis' do, so the axis stands out further from the next line.
  cv::Mat img = blank(320, 240);
  std::mt19937 rng(11);
  for (int i = 0; i < 60; ++i) {
    auto u = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const cv::Point a(u(0, 319), u(0, 239));
    cv::line(img, a, a + cv::Point(u(-30, 30), u(-30, 30)), cv::Scalar(u(0, 120)), 2);
  }
  const double r = 20.0, theta = 3.0 * kDeg;
  syn::draw_shape(img, syn::bottle_profile(170, 30), r, theta, 0, cv::Scalar(60));
  auto margin = [&](double tolerance) {
    Params p = synthetic_params();
    p.num_lines = 2;
    p.theta_min_deg = -25;
    p.theta_max_deg = 25;
    p.mirror_tolerance_deg = tolerance;
    const Result res = Detector(p).detect(img);
    EXPECT_EQ(res.lines.size(), 2u);
    if (res.lines.size() < 2) return 0.0;
    EXPECT_LT(angle_diff_deg(res.lines[0].theta, theta), 1.0) << "tolerance " << tolerance;
    EXPECT_LT(r_diff(res.lines[0], r, theta), 1.5) << "tolerance " << tolerance;
    return res.lines[0].votes / res.lines[1].votes;
  };
  const double plain = margin(0), mirrored = margin(15);
  EXPECT_GT(mirrored, 1.5 * plain) << "top / second line: " << plain << " plain, " << mirrored << " mirrored";
}

TEST(SymmetryVote, CornerCuttingBaselineCastsOnlySomeOfTheVotes) {
  const EdgeSet edges = detect_edges(syn::indoor_scene(3, 640, 480, 4), EdgeParams{1.0, 30, 90, false});
  Params p;
  p.dmin = 25;
  p.dmax = 250;
  CornerCuttingVoter voter;
  const double cast = cv::sum(voter.vote(edges, p).votes[0])[0];
  const double all = cv::sum(reference_vote(edges, p).votes[0])[0];
  EXPECT_GT(cast, 0.05 * all);
  EXPECT_LT(cast, 0.6 * all) << "the shortcut should skip many of Algorithm 1's votes";
  // A row with one valid pair and nothing else: the shortcut finds it too.
  EdgeSet pair;
  pair.width = pair.height = 101;
  pair.points = {{20, 50}, {80, 50}};
  p.dmin = 10;
  p.dmax = 0;
  p.theta_min_deg = p.theta_max_deg = 0;
  const Accumulator& acc = voter.vote(pair, p);
  EXPECT_EQ(acc.votes[0].at<int32_t>(89, acc.r_max), 1);
  p.skew_deg = {10};
  EXPECT_THROW(voter.vote(edges, p), std::invalid_argument);
}

namespace {

// Every pair-loop variant of the mirror rule: windowed checks on rows grouped by orientation
// (mirror_sorted_rows) or whole rows, portable or AVX-512 loops (vector_kernels), one thread or two.
void expect_mirror_variants_equal_plain(const EdgeSet& edges, const Params& base, bool need_votes = true) {
  const Accumulator plain = reference_vote(edges, base);
  for (bool sorted : {true, false}) {
    for (bool vector : {true, false}) {
      for (int threads : {1, 2}) {
        if (threads == 2 && !(sorted && !vector)) continue;  // two threads: on the windowed loops only
        Params p = base;
        p.mirror_sorted_rows = sorted;
        p.vector_kernels = vector;
        p.threads = threads;
        SCOPED_TRACE("sorted rows " + std::to_string(sorted) + ", vector kernels " + std::to_string(vector) +
                     ", threads " + std::to_string(threads));
        Detector d(p);
        if (need_votes) {
          expect_same_accumulator(d.vote(edges), plain);
        } else {
          const Accumulator& fast = d.vote(edges);
          ASSERT_EQ(fast.votes.size(), plain.votes.size());
          EXPECT_EQ(cv::countNonZero(fast.votes[0] != plain.votes[0]), 0);
        }
      }
    }
  }
}

// Edge pixels at random places with orientations drawn by `angle_of(rng)` (orientation units).
template <typename AngleOf>
EdgeSet random_edges(int width, int height, int count, uint32_t seed, AngleOf angle_of) {
  EdgeSet edges;
  edges.width = width;
  edges.height = height;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1);
  for (int i = 0; i < count; ++i) {
    edges.points.emplace_back(x(rng), y(rng));
    edges.orientation.push_back(angle_of(rng));
  }
  return edges;
}

}  // namespace

TEST(SymmetryVote, MirrorWindowsEqualPlainOnScenes) {
  // Dense scenes (long rows), a narrow image (16-bit loops) and one too wide for them, tolerances
  // from a fraction of an orientation bucket to everything, with once-per-row and row limits.
  struct Case {
    int width, height;
    double tolerance;
    bool once = false;
    int max_row = 0;
  };
  const std::vector<Case> cases = {{240, 180, 15}, {160, 120, 0.5}, {160, 120, 90}, {160, 120, 7, true},
                                   {160, 120, 20, false, 30}, {5600, 24, 15}};  // 5600 wide: too wide for 16-bit lanes
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    EdgeParams e{1.0, 30, 90, false};
    e.gradients = true;
    const EdgeSet edges = detect_edges(syn::indoor_scene(static_cast<uint32_t>(300 + i), c.width, c.height, 4), e);
    Params p;
    p.dmin = 5;
    p.dmax = 200;
    p.mirror_tolerance_deg = c.tolerance;
    p.once_per_row = c.once;
    p.max_row_pixels = c.max_row;
    SCOPED_TRACE("case " + std::to_string(i));
    expect_mirror_variants_equal_plain(edges, p);
  }
}

TEST(SymmetryVote, MirrorWindowsEqualPlainOnEdgeCases) {
  Params p = synthetic_params();
  p.dmin = 2;
  p.mirror_tolerance_deg = 10;
  const int16_t near_zero = orientation_units(0.3 * kDeg);  // windows that wrap past 0 / 180 deg
  {
    SCOPED_TRACE("orientations within a few degrees of 0 / 180 deg");
    const EdgeSet edges = random_edges(120, 90, 3000, 11, [&](std::mt19937& rng) {
      return static_cast<int16_t>(near_zero + std::uniform_int_distribution<int>(-2000, 2000)(rng));
    });
    expect_mirror_variants_equal_plain(edges, p);
    Params near_wrap = p;  // and axes near +-90 deg, where 2 theta wraps too
    near_wrap.theta_min_deg = 80;
    near_wrap.theta_max_deg = -80;
    expect_mirror_variants_equal_plain(edges, near_wrap);
  }
  {
    SCOPED_TRACE("vertical and horizontal edges only (0 and 90 deg: int16 -32768)");
    const EdgeSet edges = random_edges(120, 90, 3000, 12, [](std::mt19937& rng) {
      return static_cast<int16_t>(std::uniform_int_distribution<int>(0, 1)(rng) ? 0 : -32768);
    });
    expect_mirror_variants_equal_plain(edges, p);
  }
  {
    SCOPED_TRACE("every orientation, one edge pixel per image row (rows of Rot near theta = 0 hold one)");
    EdgeSet edges;
    edges.width = 200;
    edges.height = 150;
    std::mt19937 rng(13);
    for (int y = 0; y < edges.height; ++y) {
      edges.points.emplace_back(std::uniform_int_distribution<int>(0, edges.width - 1)(rng), y);
      edges.orientation.push_back(static_cast<int16_t>(std::uniform_int_distribution<int>(-32768, 32767)(rng)));
    }
    expect_mirror_variants_equal_plain(edges, p);
  }
  {
    SCOPED_TRACE("a sparse frame (most rows of Rot empty) and a single pixel");
    const EdgeSet sparse = random_edges(400, 300, 40, 14, [](std::mt19937& rng) {
      return static_cast<int16_t>(std::uniform_int_distribution<int>(-32768, 32767)(rng));
    });
    expect_mirror_variants_equal_plain(sparse, p, /*need_votes=*/false);
    const EdgeSet one = random_edges(400, 300, 1, 15, [](std::mt19937&) { return int16_t{123}; });
    expect_mirror_variants_equal_plain(one, p, /*need_votes=*/false);
  }
  {
    SCOPED_TRACE("no edge pixels");
    EdgeSet none;
    none.width = 64;
    none.height = 48;
    Detector d(p);
    EXPECT_EQ(cv::countNonZero(d.vote(none).votes[0]), 0);
  }
}

TEST(SymmetryVote, MirrorWindowsEqualPlainWhenEveryPixelHasOneOrientation) {
  // Every pixel in one orientation bucket (the other buckets of every row empty: their starts come
  // from the bucket after them), at a bucket's last and first unit, just below the 0 / 180 deg wrap
  // and mid-range; as orientations and, with polarity, as gradient directions (mod 360 deg). Dense
  // rows (1500 pixels in 100 x 75) so that windows are long; pairs vote only where 2 theta is
  // within the tolerance of twice the orientation.
  Params p = synthetic_params();
  p.dmin = 2;
  p.mirror_tolerance_deg = 10;
  const int bucket_units = 65536 / 64;  // vote.cpp's orientation buckets (6 bits)
  for (const int angle : {bucket_units - 1, bucket_units, -1, 12345}) {
    for (const bool polarity : {false, true}) {
      SCOPED_TRACE("angle units " + std::to_string(angle) + ", polarity " + std::to_string(polarity));
      EdgeSet edges = random_edges(100, 75, 1500, 21, [&](std::mt19937&) { return static_cast<int16_t>(angle); });
      Params q = p;
      q.mirror_polarity = polarity;
      if (polarity) {
        edges.direction = edges.orientation;
        // Half the pixels with the opposite contrast (direction + 180 deg): the same orientation.
        for (size_t i = 0; i < edges.direction.size(); i += 2)
          edges.direction[i] = static_cast<int16_t>(static_cast<uint16_t>(edges.direction[i]) + 32768u);
      }
      expect_mirror_variants_equal_plain(edges, q);
    }
  }
}

TEST(SymmetryVote, MirrorWindowsKeepExactlyThePairsWithinTheTolerance) {
  // One row of Rot at theta = 0 (image row y = 10) holding pixels of every orientation: the
  // windowed checks must keep a pair exactly when |a + b| <= tolerance (mod 180 deg), on both
  // sides of the bucket edges and of the 0 / 180 deg wrap.
  EdgeSet edges;
  edges.width = 400;
  edges.height = 21;
  const int count = 180;
  for (int i = 0; i < count; ++i) {
    edges.points.emplace_back(2 * i + 10, 10);
    edges.orientation.push_back(orientation_units((i * 7 % count) * kDeg + 0.01 * kDeg));
  }
  Params p = synthetic_params();
  p.dmin = 0.5;
  p.theta_min_deg = p.theta_max_deg = 0;
  p.mirror_tolerance_deg = 4;
  long expected = 0;
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) {
      const int error = std::abs(static_cast<int16_t>(static_cast<uint16_t>(edges.orientation[i] + edges.orientation[j])));
      expected += error <= static_cast<int>(std::round(4 * 65536.0 / 180.0));
    }
  ASSERT_GT(expected, count);  // each pixel has partners: the count is a real check
  for (bool vector : {true, false}) {
    p.vector_kernels = vector;
    Detector d(p);
    EXPECT_EQ(cv::sum(d.vote(edges).votes[0])[0], static_cast<double>(expected)) << "vector kernels " << vector;
  }
  expect_mirror_variants_equal_plain(edges, p);
}

TEST(SymmetryVote, MirrorPolarityKeepsOnlyPairsOfTheSameContrast) {
  // Pixels mirror-symmetric about the vertical line x = 100 (R = 0, theta = 0). Gradient
  // directions of a mirrored pair with the same contrast on both sides: a and 180 deg - a.
  EdgeSet edges;
  edges.width = edges.height = 201;
  std::mt19937 rng(6);
  for (int y = 20; y < 180; y += 2) {
    const int dx = std::uniform_int_distribution<int>(15, 80)(rng);
    edges.points.emplace_back(100 - dx, y);
    edges.points.emplace_back(100 + dx, y);
  }
  auto axis_votes = [&](double left_deg, double right_deg, bool polarity) {
    edges.orientation.clear();
    edges.direction.clear();
    for (size_t i = 0; i < edges.points.size(); ++i) {
      const double angle = (i % 2 == 0 ? left_deg : right_deg) * kDeg;
      edges.orientation.push_back(orientation_units(angle));
      edges.direction.push_back(direction_units(angle));
    }
    Params p = synthetic_params();
    p.mirror_tolerance_deg = 10;
    p.mirror_polarity = polarity;
    Detector d(p);
    const Accumulator& acc = d.vote(edges);
    expect_same_accumulator(acc, reference_vote(edges, p));
    return acc.votes[0].at<int32_t>(89 /* theta 0 */, acc.r_max /* R 0 */);
  };
  const int all = axis_votes(30, 150, false);
  ASSERT_GE(all, 80);
  EXPECT_EQ(axis_votes(30, 150, true), all);   // same contrast: mirrored directions
  EXPECT_EQ(axis_votes(0, 180, true), all);    // a vertical outline, dark outside on both sides
  EXPECT_EQ(axis_votes(30, 142, true), all);   // 8 deg off: inside the tolerance
  EXPECT_EQ(axis_votes(30, 330, false), all);  // opposite contrast: the orientation rule keeps it...
  EXPECT_EQ(axis_votes(30, 330, true), 0);     // ...the polarity rule drops it
  EXPECT_EQ(axis_votes(0, 0, true), 0);        // a step edge seen twice, both gradients pointing right
}

TEST(SymmetryVote, MirrorPolarityFastEqualsPlain) {
  EdgeParams e{1.0, 30, 90, false};
  e.gradients = true;
  const EdgeSet edges = detect_edges(syn::indoor_scene(41, 240, 180, 4), e);
  ASSERT_EQ(edges.direction.size(), edges.points.size());
  for (size_t i = 0; i < edges.points.size(); ++i)  // the direction modulo 180 deg is the orientation
    ASSERT_LE(std::abs(static_cast<int16_t>(static_cast<uint16_t>(2 * edges.direction[i] - edges.orientation[i]))), 2);
  Params p;
  p.dmin = 5;
  p.dmax = 200;
  p.mirror_tolerance_deg = 15;
  p.mirror_polarity = true;
  expect_mirror_variants_equal_plain(edges, p);
  Params wrap = p;  // axes near +-90 deg
  wrap.theta_min_deg = 75;
  wrap.theta_max_deg = -75;
  expect_mirror_variants_equal_plain(edges, wrap);
}

TEST(SymmetryVote, MirrorFastPathEqualsPlainOnOddSizesLongRowsAndToleranceExtremes) {
  // The mirror rule's fast path on the 16-bit AVX-512 loops (mirror_sorted_rows, vector_kernels:
  // ranked row sort, the rule as one unsigned compare, pair sums shifted in the histogram) against
  // the plain loop, with and without polarity: odd image sizes (pixel centres at half-integer
  // doubled coordinates), rows of a thousand pixels (large ranks, many 32-lane steps per pixel, no
  // distance limits), and tolerances at both ends (0 units: only exact mirrors; 90 deg: every
  // pair but one angle error).
  auto any_angle = [](std::mt19937& rng) {
    return static_cast<int16_t>(std::uniform_int_distribution<int>(-32768, 32767)(rng));
  };
  auto with_directions = [&](EdgeSet edges, uint32_t seed) {
    std::mt19937 rng(seed);
    for (size_t i = 0; i < edges.points.size(); ++i) edges.direction.push_back(any_angle(rng));
    return edges;
  };
  struct Case {
    std::string name;
    EdgeSet edges;
    double dmin, dmax, tolerance;
  };
  std::vector<Case> cases;
  cases.push_back({"161 x 97", with_directions(random_edges(161, 97, 2500, 31, any_angle), 32), 3, 120, 15});
  cases.push_back({"33 x 17", with_directions(random_edges(33, 17, 300, 33, any_angle), 34), 1, 40, 20});
  cases.push_back({"7 x 301", with_directions(random_edges(7, 301, 900, 35, any_angle), 36), 0, 0, 30});
  cases.push_back({"161 x 97, tolerance 0 units", with_directions(random_edges(161, 97, 2500, 37, [](std::mt19937& rng) {
                     return static_cast<int16_t>(std::uniform_int_distribution<int>(-3, 3)(rng) * 4096);
                   }), 38), 2, 150, 0.001});
  cases.push_back({"161 x 97, tolerance 90 deg", with_directions(random_edges(161, 97, 1500, 39, any_angle), 40), 2, 150, 90});
  {
    EdgeSet full;  // every pixel of a 1001 x 3 image: rows of Rot up to 1001 pixels long
    full.width = 1001;
    full.height = 3;
    std::mt19937 rng(41);
    for (int y = 0; y < full.height; ++y)
      for (int x = 0; x < full.width; ++x) {
        full.points.emplace_back(x, y);
        full.orientation.push_back(any_angle(rng));
      }
    cases.push_back({"1001 x 3, every pixel", with_directions(full, 42), 0, 0, 10});
  }
  for (const Case& c : cases) {
    for (const bool polarity : {false, true}) {
      SCOPED_TRACE(c.name + ", polarity " + std::to_string(polarity));
      Params p = synthetic_params();
      p.dmin = c.dmin;
      p.dmax = c.dmax;
      p.mirror_tolerance_deg = c.tolerance;
      p.mirror_polarity = polarity;
      expect_mirror_variants_equal_plain(c.edges, p);
    }
  }
}

TEST(SymmetryBadInput, MirrorPolarityNeedsTheRuleAndDirections) {
  Params p;
  p.mirror_polarity = true;
  try {
    validate(p);
    ADD_FAILURE() << "polarity without the mirror rule accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mirror_polarity"), std::string::npos) << e.what();
  }
  p.mirror_tolerance_deg = 15;
  EdgeSet edges = edges_from_mask(cv::Mat::ones(20, 20, CV_8U));
  edges.orientation.assign(edges.points.size(), 0);  // orientations, but no directions
  Detector d(p);
  try {
    d.vote(edges);
    ADD_FAILURE() << "polarity without directions accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("direction"), std::string::npos) << e.what();
  }
}

TEST(SymmetryVote, ThreadsGiveTheSameAccumulator) {
  const cv::Mat scene = syn::indoor_scene(7);
  const EdgeSet edges = detect_edges(scene, EdgeParams{1.0, 30, 90, false});
  Params one;
  Params two = one;
  two.threads = 2;
  Detector a(one), b(two);
  expect_same_accumulator(a.vote(edges), b.vote(edges));
}

TEST(SymmetryDetect, FindsAxisBetweenBinsToSubBinPrecision) {
  // True axes between the 1 deg / 1 px bins.
  const std::vector<std::pair<double, double>> axes = {{40.5, 12.5}, {-25.5, -7.5}, {10.5, 33.5}, {0.5, 0.5}};
  for (const auto& [r, theta_deg] : axes) {
    cv::Mat img = blank();
    syn::draw_shape(img, syn::bottle_profile(150, 28), r, theta_deg * kDeg, 0, cv::Scalar(40));
    Params p = synthetic_params();
    p.num_lines = 1;
    p.theta_min_deg = -60;  // upright-ish objects: keeps the self-symmetric straight sides out
    p.theta_max_deg = 60;
    Detector detector(p);
    const Result res = detector.detect(img);
    ASSERT_EQ(res.lines.size(), 1u);
    EXPECT_LT(angle_diff_deg(res.lines[0].theta, theta_deg * kDeg), 0.25) << "theta " << theta_deg;
    EXPECT_LT(r_diff(res.lines[0], r, theta_deg * kDeg), 0.5) << "r " << r;
  }
}

TEST(SymmetryDetect, AxesAcrossTheNinetyDegreeWrap) {
  // Nearly horizontal axes: theta close to +-90 where the accumulator wraps with R mirrored.
  for (double theta_deg : {89.6, -89.4, 88.0}) {
    cv::Mat img = blank(240, 320);
    syn::draw_shape(img, syn::bottle_profile(150, 30), 12.0, theta_deg * kDeg, 0, cv::Scalar(30));
    Params p = synthetic_params();
    p.num_lines = 1;
    const Result res = Detector(p).detect(img);
    ASSERT_EQ(res.lines.size(), 1u);
    EXPECT_LT(angle_diff_deg(res.lines[0].theta, theta_deg * kDeg), 0.5) << theta_deg;
    EXPECT_LT(r_diff(res.lines[0], 12.0, theta_deg * kDeg), 1.0) << theta_deg;
    EXPECT_GT(res.lines[0].theta, -M_PI / 2);
    EXPECT_LE(res.lines[0].theta, M_PI / 2);
  }
}

TEST(SymmetryDetect, FindsSeveralShapes) {
  cv::Mat img = blank(640, 480);
  const std::vector<std::pair<double, double>> axes = {{-200, 3}, {-60, -4}, {90, 0}, {220, 6}};
  for (size_t i = 0; i < axes.size(); ++i) {
    syn::draw_shape(img, i % 2 ? syn::cup_profile(120, 40, 32) : syn::bottle_profile(200, 35), axes[i].first,
                    axes[i].second * kDeg, 20, cv::Scalar(30 + 40 * i));
  }
  Params p;  // thesis indoor parameters, orientation limits for upright objects
  p.num_lines = 5;
  p.theta_min_deg = -25;
  p.theta_max_deg = 25;
  const Result res = Detector(p).detect(img);
  for (const auto& [r, t] : axes) {
    bool found = false;
    for (const auto& l : res.lines) found |= angle_diff_deg(l.theta, t * kDeg) < 1.0 && r_diff(l, r, t * kDeg) < 1.5;
    EXPECT_TRUE(found) << "axis r=" << r << " theta=" << t << " not among the lines";
  }
}

TEST(SymmetryDetect, MugHandleAndNoiseKeepTheBodyAxisOnTop) {
  cv::Mat img = blank(320, 240);
  const double r = -12.0, theta = 4.0 * kDeg;
  syn::draw_mug(img, r, theta, 0, 130, 45, cv::Scalar(50));
  Params p = synthetic_params();
  p.num_lines = 1;
  p.theta_min_deg = -25;  // thesis: +-15..25 deg of vertical for upright objects
  p.theta_max_deg = 25;
  EdgeSet edges = detect_edges(img, EdgeParams{});
  const Result clean = Detector(p).detect(edges);
  ASSERT_EQ(clean.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(clean.lines[0].theta, theta), 1.0);
  EXPECT_LT(r_diff(clean.lines[0], r, theta), 1.0);
  // 50 % extra random edge pixels.
  std::mt19937 rng(3);
  const size_t extra = edges.points.size() / 2;
  for (size_t i = 0; i < extra; ++i) {
    edges.points.emplace_back(std::uniform_int_distribution<int>(0, img.cols - 1)(rng),
                              std::uniform_int_distribution<int>(0, img.rows - 1)(rng));
  }
  const Result noisy = Detector(p).detect(edges);
  ASSERT_EQ(noisy.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(noisy.lines[0].theta, theta), 1.0);
  EXPECT_LT(r_diff(noisy.lines[0], r, theta), 1.0);
}

TEST(SymmetryDetect, OncePerRowStopsAStraightEdgeOutvotingAUContour) {
  // Fig. 3.4: a long straight edge (many collinear pixels in one row of Rot) against a U.
  EdgeSet edges;
  edges.width = 400;
  edges.height = 300;
  for (int x = 20; x < 220; ++x) edges.points.emplace_back(x, 40);  // straight edge, centre x = 119.5
  for (int y = 150; y < 250; ++y) {                                   // U contour, axis x = 300
    edges.points.emplace_back(260, y);
    edges.points.emplace_back(340, y);
  }
  for (int x = 260; x <= 340; ++x) edges.points.emplace_back(x, 250);
  Params p = synthetic_params();
  p.num_lines = 1;
  p.min_peak_ratio = 0;
  const Result plain = Detector(p).detect(edges);
  ASSERT_EQ(plain.lines.size(), 1u);
  // Without the rule the straight edge, symmetric about its own perpendicular bisector, wins.
  EXPECT_LT(angle_diff_deg(plain.lines[0].theta, 0), 0.5);
  EXPECT_NEAR(plain.lines[0].r, 119.5 - 199.5, 1.0);
  p.once_per_row = true;
  const Result once = Detector(p).detect(edges);
  ASSERT_EQ(once.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(once.lines[0].theta, 0), 0.5);
  EXPECT_NEAR(once.lines[0].r, 300 - 199.5, 0.6);
}

TEST(SymmetryDetect, SupportSegmentCoversTheShape) {
  cv::Mat img = blank();
  syn::draw_shape(img, syn::bottle_profile(100, 25), 0, 0, 0, cv::Scalar(30));
  Params p = synthetic_params();
  p.num_lines = 1;
  p.theta_min_deg = -30;
  p.theta_max_deg = 30;
  const Result res = Detector(p).detect(img);
  ASSERT_EQ(res.lines.size(), 1u);
  const Line& l = res.lines[0];
  const double top = std::min(l.seg1.y, l.seg2.y), bottom = std::max(l.seg1.y, l.seg2.y);
  EXPECT_NEAR(top, 119.5 - 50, 3.0);
  EXPECT_NEAR(bottom, 119.5 + 50, 3.0);
  EXPECT_NEAR(l.seg1.x, 159.5, 1.0);
  // The border endpoints span the whole image height.
  EXPECT_NEAR(std::min(l.end1.y, l.end2.y), 0, 1e-6);
  EXPECT_NEAR(std::max(l.end1.y, l.end2.y), 239, 1e-6);
}

TEST(SymmetryDetect, RecoversSkewAngle) {
  // A sheared bottle: horizontal chords, midpoints on an axis tilted by the skew angle; not
  // bilaterally symmetric about any line.
  EdgeSet edges;
  edges.width = 320;
  edges.height = 240;
  const double skew = 20 * kDeg;
  const syn::Profile profile = syn::bottle_profile(140, 40);
  for (size_t i = 0; i < profile.half_width.size(); ++i) {
    const int y = 50 + static_cast<int>(i);
    const double mid = 160 + (y - 119.5) * std::tan(skew);
    edges.points.emplace_back(static_cast<int>(std::lround(mid - profile.half_width[i])), y);
    edges.points.emplace_back(static_cast<int>(std::lround(mid + profile.half_width[i])), y);
  }
  Params p = synthetic_params();
  p.num_lines = 1;
  p.skew_deg = {-20, -10, 10, 20};
  p.once_per_row = true;  // the straight sides would otherwise vote for their own bisectors
  const Result res = Detector(p).detect(edges);
  ASSERT_EQ(res.lines.size(), 1u);
  EXPECT_NEAR(std::fabs(res.lines[0].skew), 20 * kDeg, 1e-9);
  // The axis itself is tilted by the skew angle from vertical.
  EXPECT_LT(angle_diff_deg(res.lines[0].theta, -skew), 1.0);
}

TEST(SymmetryDetect, OrientationLimitsExcludeOtherAngles) {
  // Two bottles, axes at 5 and 30 deg: the limits keep the first and must drop the second.
  cv::Mat img = blank();
  syn::draw_shape(img, syn::bottle_profile(150, 28), -70, 5 * kDeg, 0, cv::Scalar(40));
  syn::draw_shape(img, syn::bottle_profile(150, 28), 70, 30 * kDeg, 0, cv::Scalar(40));
  auto has_axis = [](const Result& res, double r, double theta_deg) {
    for (const auto& l : res.lines)
      if (angle_diff_deg(l.theta, theta_deg * kDeg) < 1.0 && r_diff(l, r, theta_deg * kDeg) < 1.5) return true;
    return false;
  };
  Params p = synthetic_params();
  EXPECT_TRUE(has_axis(Detector(p).detect(img), 70, 30));  // without limits the 30 deg axis is found
  p.theta_min_deg = -15;
  p.theta_max_deg = 15;
  const Result res = Detector(p).detect(img);
  ASSERT_FALSE(res.lines.empty());
  EXPECT_TRUE(has_axis(res, -70, 5));
  for (const auto& l : res.lines) EXPECT_LE(std::fabs(l.theta) / kDeg, 16.0);
}

// Sub-bin refinement (eq. 3.1-3.2) on hand-made accumulators, checked against the Newton step and
// the 1D parabola vertices worked out here.
namespace {
Accumulator one_peak(int r_max, int theta_bin, int r_bin, const std::array<std::array<int, 3>, 3>& votes) {
  Accumulator acc;
  acc.r_max = r_max;
  acc.votes = {cv::Mat(kThetaBins, acc.num_r(), CV_32S, cv::Scalar(0))};
  for (int dt = -1; dt <= 1; ++dt)
    for (int dr = -1; dr <= 1; ++dr) acc.votes[0].at<int32_t>(theta_bin + dt, r_bin + dr) = votes[dt + 1][dr + 1];
  return acc;
}
}  // namespace

TEST(SymmetryPeaks, SubBinNewtonStepRecoversAQuadraticPeak) {
  // V(dr, dt) = 10000 - 1000 (2 (dr - 0.3)^2 + 1.5 (dt + 0.2)^2 + 0.8 (dr - 0.3)(dt + 0.2)): a
  // quadratic, so the 3x3 finite differences are exact and the Newton step lands on its top.
  const double r0 = 0.3, t0 = -0.2;
  auto v = [&](int dr, int dt) {
    const double x = dr - r0, y = dt - t0;
    return static_cast<int>(std::lround(10000 - 1000 * (2 * x * x + 1.5 * y * y + 0.8 * x * y)));
  };
  std::array<std::array<int, 3>, 3> votes{};
  for (int dt = -1; dt <= 1; ++dt)
    for (int dr = -1; dr <= 1; ++dr) votes[dt + 1][dr + 1] = v(dr, dt);
  const Accumulator acc = one_peak(50, 100, 70, votes);
  Params p;
  p.num_lines = 1;
  p.refine_log = false;
  const std::vector<Line> lines = Detector(p).find_peaks(acc, 101, 101);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].r, 70 + r0 - 50, 2e-3);
  EXPECT_NEAR(lines[0].theta / kDeg, theta_of_bin_deg(100 + t0), 2e-3);
  EXPECT_EQ(lines[0].r_bin, 70);
  EXPECT_EQ(lines[0].theta_bin, 100);
}

TEST(SymmetryPeaks, NewtonStepOutsideTheBinFallsBackToSeparateParabolas) {
  // Centre 100; along R 60 | 100 | 90, along theta 70 | 100 | 80; strong corners (hrt = 40 against
  // hrr = htt = -50) put the Newton step outside the bin (dr = 950 / 900), so each direction gets
  // its own parabola: dr = -gr / hrr = 15 / 50 = 0.3, dt = -gt / htt = 5 / 50 = 0.1.
  const std::array<std::array<int, 3>, 3> votes = {{{95, 70, 15}, {60, 100, 90}, {15, 80, 95}}};
  Params p;
  p.num_lines = 1;
  p.refine_log = false;
  std::vector<Line> lines = Detector(p).find_peaks(one_peak(50, 90, 60, votes), 101, 101);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].r, 60 + 0.3 - 50, 1e-9);
  EXPECT_NEAR(lines[0].theta / kDeg, theta_of_bin_deg(90 + 0.1), 1e-9);

  // The same on log(1 + V) (the default), corners 75 / 25 (log Newton step 2.45 bins): the
  // vertices of the parabolas through the log votes.
  const std::array<std::array<int, 3>, 3> log_votes = {{{75, 70, 25}, {60, 100, 90}, {25, 80, 75}}};
  p.refine_log = true;
  lines = Detector(p).find_peaks(one_peak(50, 90, 60, log_votes), 101, 101);
  ASSERT_EQ(lines.size(), 1u);
  auto vertex = [](double minus, double centre, double plus) {
    const double a = std::log1p(minus), b = std::log1p(centre), c = std::log1p(plus);
    return -((c - a) / 2) / (c + a - 2 * b);
  };
  EXPECT_NEAR(lines[0].r, 60 + vertex(60, 100, 90) - 50, 1e-6);
  EXPECT_NEAR(lines[0].theta / kDeg, theta_of_bin_deg(90 + vertex(70, 100, 80)), 1e-6);
}

TEST(SymmetryPeaks, RefinementAcrossTheThetaWrapReadsTheMirroredRow) {
  // Peak in theta bin 0 (-89 deg): its theta neighbour below is bin 179 with R mirrored (column
  // num_r - 1 - b). Along R 60 | 100 | 60, along theta 70 (bin 179, mirrored) | 100 | 80 (bin 1),
  // corners 0: dr = 0, dt = -gt / htt = 5 / 50 = 0.1 (plain votes).
  const int r_max = 50, b = 60;
  Accumulator acc = one_peak(r_max, 1, b, {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}});  // zeros
  cv::Mat& v = acc.votes[0];
  v.at<int32_t>(0, b) = 100;
  v.at<int32_t>(0, b - 1) = v.at<int32_t>(0, b + 1) = 60;
  v.at<int32_t>(1, b) = 80;
  v.at<int32_t>(kThetaBins - 1, acc.num_r() - 1 - b) = 70;
  Params p;
  p.num_lines = 1;
  p.refine_log = false;
  std::vector<Line> lines = Detector(p).find_peaks(acc, 101, 101);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].r, b - r_max, 1e-9);
  EXPECT_NEAR(lines[0].theta / kDeg, theta_of_bin_deg(0.1), 1e-9);

  // The same peak in bin 179 (+90 deg), rising towards bin 0: refined past +90 deg, the line is
  // reported as theta - 180 with R negated.
  Accumulator top = one_peak(r_max, 1, b, {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}});
  cv::Mat& t = top.votes[0];
  t.at<int32_t>(kThetaBins - 1, b) = 100;
  t.at<int32_t>(kThetaBins - 1, b - 1) = t.at<int32_t>(kThetaBins - 1, b + 1) = 60;
  t.at<int32_t>(kThetaBins - 2, b) = 70;
  t.at<int32_t>(0, top.num_r() - 1 - b) = 80;
  lines = Detector(p).find_peaks(top, 101, 101);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].theta / kDeg, theta_of_bin_deg(kThetaBins - 1 + 0.1) - 180, 1e-9);
  EXPECT_NEAR(lines[0].r, -(b - r_max), 1e-9);
}

TEST(SymmetryPeaks, PeaksBelowTheRatioOfTheHighestAreDropped) {
  // Peaks of 1000 and 60 far apart: with min_peak_ratio 0.1 only the first is a line, with 0.05 both.
  Accumulator acc = one_peak(50, 40, 20, {{{0, 0, 0}, {0, 1000, 0}, {0, 0, 0}}});
  acc.votes[0].at<int32_t>(120, 80) = 60;
  Params p;
  p.num_lines = 5;
  p.min_peak_ratio = 0.1;
  EXPECT_EQ(Detector(p).find_peaks(acc, 101, 101).size(), 1u);
  p.min_peak_ratio = 0.05;
  const std::vector<Line> lines = Detector(p).find_peaks(acc, 101, 101);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NEAR(lines[1].r, 80 - 50, 1e-9);
  EXPECT_NEAR(lines[1].theta / kDeg, theta_of_bin_deg(120), 1e-9);
}

TEST(SymmetryDetect, RecoversTheSkewAxisOffTheCentre) {
  // RecoversSkewAngle's sheared bottle 60 px right of the centre: the axis x' = 60.5 + y' tan(phi)
  // is the line (60.5 cos(phi), -phi).
  EdgeSet edges;
  edges.width = 320;
  edges.height = 240;
  const double skew = 20 * kDeg;
  const syn::Profile profile = syn::bottle_profile(140, 40);
  for (size_t i = 0; i < profile.half_width.size(); ++i) {
    const int y = 50 + static_cast<int>(i);
    const double mid = 220 + (y - 119.5) * std::tan(skew);
    edges.points.emplace_back(static_cast<int>(std::lround(mid - profile.half_width[i])), y);
    edges.points.emplace_back(static_cast<int>(std::lround(mid + profile.half_width[i])), y);
  }
  Params p = synthetic_params();
  p.num_lines = 1;
  p.skew_deg = {-20, -10, 10, 20};
  p.once_per_row = true;
  const Result res = Detector(p).detect(edges);
  ASSERT_EQ(res.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(res.lines[0].theta, -skew), 1.0);
  EXPECT_LT(r_diff(res.lines[0], 60.5 * std::cos(skew), -skew), 1.5);
}

TEST(SymmetryPeaks, NonMaximumSuppressionCoversItsWholeWindow) {
  // Around the peak (theta bin 90, R bin 50) every bin within suppress_r = 10 R bins and
  // suppress_theta = 10 theta bins is suppressed, the window's edges included; 11 bins off is not.
  Accumulator acc = one_peak(50, 90, 50, {{{0, 0, 0}, {0, 1000, 0}, {0, 0, 0}}});
  cv::Mat& v = acc.votes[0];
  v.at<int32_t>(90, 60) = 900;   // R edge of the window
  v.at<int32_t>(100, 50) = 800;  // theta edge of the window
  v.at<int32_t>(90, 40) = 850;   // the other R edge
  v.at<int32_t>(80, 50) = 820;   // the other theta edge
  v.at<int32_t>(90, 61) = 700;   // just outside
  Params p;
  p.num_lines = 5;
  const std::vector<Line> lines = Detector(p).find_peaks(acc, 101, 101);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].r_bin, 50);
  EXPECT_EQ(lines[1].r_bin, 61);
  EXPECT_EQ(lines[1].theta_bin, 90);
}

TEST(SymmetryVote, PairDistanceLimitsAreInclusiveAndInPixels) {
  // One pair 20 px apart on a row: at theta = 0 (bin 89) it votes iff Dmin <= 20 <= Dmax.
  EdgeSet edges;
  edges.width = 320;
  edges.height = 240;
  edges.points = {{100, 50}, {120, 50}};
  auto votes_at_theta0 = [&](double dmin, double dmax) {
    Params p;
    p.dmin = dmin;
    p.dmax = dmax;
    const int plain = cv::countNonZero(reference_vote(edges, p).votes[0].row(89));
    Detector fast(p);
    EXPECT_EQ(cv::countNonZero(fast.vote(edges).votes[0].row(89)), plain) << dmin << " " << dmax;
    return plain;
  };
  EXPECT_EQ(votes_at_theta0(25, 250), 0);  // too close
  EXPECT_EQ(votes_at_theta0(20, 250), 1);  // exactly Dmin
  EXPECT_EQ(votes_at_theta0(21, 250), 0);
  EXPECT_EQ(votes_at_theta0(5, 20), 1);    // exactly Dmax
  EXPECT_EQ(votes_at_theta0(5, 19.5), 0);  // too far
}

TEST(SymmetryBadInput, EmptyImageIsAClearError) {
  Detector d;
  EXPECT_THROW(d.detect(cv::Mat()), std::invalid_argument);
}

TEST(SymmetryBadInput, TinyAndEdgelessImagesGiveNoLines) {
  Detector d;
  EXPECT_TRUE(d.detect(cv::Mat(1, 1, CV_8UC1, cv::Scalar(0))).lines.empty());
  EXPECT_TRUE(d.detect(cv::Mat(2, 5, CV_8UC3, cv::Scalar(9, 9, 9))).lines.empty());
  const Result flat = d.detect(blank());
  EXPECT_EQ(flat.num_edges, 0);
  EXPECT_TRUE(flat.lines.empty());
}

TEST(SymmetryBadInput, BadParametersAreRejectedNamingTheParameter) {
  auto message_of = [](Params p) {
    try {
      Detector d(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Params p;
  p.dmin = 300;
  p.dmax = 100;
  EXPECT_NE(message_of(p).find("dmin"), std::string::npos);
  p = Params{};
  p.theta_min_deg = -120;
  EXPECT_NE(message_of(p).find("theta_min"), std::string::npos);
  p = Params{};
  p.theta_max_deg = std::nan("");
  EXPECT_NE(message_of(p).find("theta_max"), std::string::npos);
  p = Params{};
  p.dmin = std::nan("");
  EXPECT_NE(message_of(p).find("dmin"), std::string::npos);
  p = Params{};
  p.dmax = std::nan("");
  EXPECT_NE(message_of(p).find("dmax"), std::string::npos);
  p = Params{};
  p.mirror_tolerance_deg = 120;
  EXPECT_NE(message_of(p).find("mirror_tolerance"), std::string::npos);
  p.mirror_tolerance_deg = std::nan("");
  EXPECT_NE(message_of(p).find("mirror_tolerance"), std::string::npos);
  p.mirror_tolerance_deg = 10;
  p.skew_deg = {20};
  EXPECT_NE(message_of(p).find("skew"), std::string::npos);
  EdgeParams e;
  e.canny_low = 100;
  e.canny_high = 10;
  EXPECT_THROW(Detector(Params{}, e), std::invalid_argument);
}

TEST(SymmetryBadInput, MirrorRuleWithoutOrientationsIsAClearError) {
  Params p;
  p.mirror_tolerance_deg = 15;
  Detector d(p);
  EdgeSet edges = detect_edges(syn::indoor_scene(1, 160, 120, 2), EdgeParams{});
  ASSERT_TRUE(edges.orientation.empty());
  try {
    d.vote(edges);
    FAIL() << "voting without orientations was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("orientation"), std::string::npos) << e.what();
  }
  // From an image the detector measures the orientations itself.
  EXPECT_GT(d.detect(syn::indoor_scene(1, 160, 120, 2)).num_edges, 0);
}

TEST(SymmetryGeometry, BorderEndpointsOfVerticalAndDiagonalLines) {
  cv::Point2d a, b;
  border_endpoints(10, 0, 101, 51, &a, &b);
  EXPECT_NEAR(a.x, 60, 1e-9);
  EXPECT_NEAR(b.x, 60, 1e-9);
  EXPECT_NEAR(std::min(a.y, b.y), 0, 1e-9);
  EXPECT_NEAR(std::max(a.y, b.y), 50, 1e-9);
  border_endpoints(0, M_PI / 4, 101, 101, &a, &b);  // anti-diagonal through the centre
  EXPECT_NEAR(a.x + a.y, 100, 1e-9);
  EXPECT_NEAR(b.x + b.y, 100, 1e-9);
  EXPECT_NEAR(std::fabs(a.x - b.x), 100, 1e-9);
}

TEST(SymmetryGeometry, ThetaRangesIncludingWrap) {
  EXPECT_EQ(theta_bins_in_range(-90, 90).size(), 180u);
  EXPECT_EQ(theta_bins_in_range(-15, 15).size(), 31u);
  const auto wrap = theta_bins_in_range(80, -80);  // 80..90 and -89..-80
  EXPECT_EQ(wrap.size(), 21u);
  EXPECT_EQ(theta_bins_in_range(0, 0).size(), 1u);
}

TEST(GeneralizedSymmetry, PeaksOnTheAxisOfAMirrorSymmetricShape) {
  cv::Mat img(41, 41, CV_8UC1, cv::Scalar(200));
  cv::rectangle(img, cv::Rect(12, 8, 17, 25), cv::Scalar(30), cv::FILLED);  // axis x = 20
  const GstResult g = generalized_symmetry(img, GstParams{50.0, 1e-6});
  ASSERT_GT(g.pairs, 0);
  // The column through the axis collects more symmetry than the columns 5 px to either side.
  const double on_axis = cv::sum(g.magnitude.col(20))[0];
  EXPECT_GT(on_axis, 2 * cv::sum(g.magnitude.col(15))[0]);
  EXPECT_GT(on_axis, 2 * cv::sum(g.magnitude.col(25))[0]);
  EXPECT_THROW(generalized_symmetry(cv::Mat(), GstParams{}), std::invalid_argument);
}

TEST(SymmetryGeometry, MapLineBetweenImageSizes) {
  // Detect in a half-size copy, map back: the line matches detection at full size.
  cv::Mat full(480, 640, CV_8UC1, cv::Scalar(220));
  syn::draw_shape(full, syn::bottle_profile(300, 50), 37.0, 6.0 * kDeg, 0, cv::Scalar(40));
  cv::Mat half;
  cv::resize(full, half, {320, 240}, 0, 0, cv::INTER_AREA);
  Params p = synthetic_params();
  p.num_lines = 1;
  p.theta_min_deg = -45;
  p.theta_max_deg = 45;
  const Result small = Detector(p).detect(half);
  ASSERT_EQ(small.lines.size(), 1u);
  const Line mapped = map_line(small.lines[0], half.size(), full.size());
  EXPECT_LT(angle_diff_deg(mapped.theta, 6.0 * kDeg), 0.5);
  EXPECT_NEAR(mapped.r, 37.0, 1.0);
  // The support segment scales with the image.
  EXPECT_NEAR(cv::norm(mapped.seg1 - mapped.seg2), 2 * cv::norm(small.lines[0].seg1 - small.lines[0].seg2), 2.0);
}

TEST(SymmetryGeometry, DropWeakLinesKeepsThoseNearTheStrongestInOrder) {
  auto line = [](double r, double votes) {
    Line l;
    l.r = r;
    l.votes = votes;
    return l;
  };
  std::vector<Line> lines{line(1, 50), line(2, 400), line(3, 39), line(4, 40)};
  drop_weak_lines(lines, 0.1);  // the strongest need not come first
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].r, 1);
  EXPECT_EQ(lines[1].r, 2);
  EXPECT_EQ(lines[2].r, 4);
  drop_weak_lines(lines, 0.0);
  EXPECT_EQ(lines.size(), 3u);
  std::vector<Line> none;
  drop_weak_lines(none, 0.5);
  EXPECT_TRUE(none.empty());
}

TEST(SymmetryEdges, DetectionLeavesTheCallersImageUntouched) {
  cv::Mat img = blank();
  syn::draw_shape(img, syn::bottle_profile(150, 28), 0, 0, 0, cv::Scalar(40));
  const cv::Mat copy = img.clone();
  detect_edges(img, EdgeParams{2.0, 30, 90, false});
  EXPECT_EQ(cv::norm(img, copy, cv::NORM_INF), 0);
}

namespace {
// A cluttered scene made exactly mirror-symmetric about the line (r, theta): each pixel on the
// negative side shows its mirror image on the positive side.
cv::Mat mirror_scene(double r, double theta, uint32_t seed) {
  const cv::Mat base = syn::indoor_scene(seed, 400, 300, 4);
  const cv::Point2d n(std::cos(theta), std::sin(theta)), c(199.5, 149.5);
  cv::Mat map_x(base.size(), CV_32F), map_y(base.size(), CV_32F);
  for (int y = 0; y < base.rows; ++y)
    for (int x = 0; x < base.cols; ++x) {
      const cv::Point2d p(x, y);
      const double side = (p - c).dot(n) - r;
      const cv::Point2d q = side >= 0 ? p : p - 2 * side * n;
      map_x.at<float>(y, x) = static_cast<float>(q.x);
      map_y.at<float>(y, x) = static_cast<float>(q.y);
    }
  cv::Mat out;
  cv::remap(base, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}
}  // namespace

TEST(LoyEklundh, FindsTheMirrorAxisOfASymmetricTexturedScene) {
  for (const auto& [r, theta_deg] : std::vector<std::pair<double, double>>{{15, 20}, {-30, -35}}) {
    const auto lines = loy_eklundh(mirror_scene(r, theta_deg * kDeg, 5));
    ASSERT_FALSE(lines.empty());
    EXPECT_LT(angle_diff_deg(lines[0].theta, theta_deg * kDeg), 2.0) << theta_deg;
    EXPECT_LT(r_diff(lines[0], r, theta_deg * kDeg), 3.0) << r;
  }
  EXPECT_THROW(loy_eklundh(cv::Mat()), std::invalid_argument);
}

TEST(PhotoDetection, LargeImagesAreDetectedAtWorkingSizeAndMappedBack) {
  cv::Mat img(960, 1280, CV_8UC3, cv::Scalar(200, 210, 220));
  syn::draw_shape(img, syn::bottle_profile(600, 100), -150.0, 4.0 * kDeg, 0, cv::Scalar(40, 50, 60));
  PhotoOptions options;
  options.params.num_lines = 1;
  options.params.theta_min_deg = -45;
  options.params.theta_max_deg = 45;
  const PhotoDetection found = detect_photo(img, options);
  EXPECT_EQ(found.working_image.cols, 480);
  ASSERT_EQ(found.in_image.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(found.in_image.lines[0].theta, 4.0 * kDeg), 1.0);
  EXPECT_NEAR(found.in_image.lines[0].r, -150.0, 3.0);
  EXPECT_EQ(found.in_image.width, 1280);
  // Photographs use mirror-consistent pairs by default, with orientations measured for them.
  EXPECT_GT(found.params.mirror_tolerance_deg, 0);
  EXPECT_TRUE(found.edge_params.gradients);
  EXPECT_EQ(found.edges.orientation.size(), found.edges.points.size());
  // ...and without the rule the edges carry no orientations (no Sobel pass to pay for).
  options.params.mirror_tolerance_deg = 0;
  const PhotoDetection plain = detect_photo(img, options);
  EXPECT_TRUE(plain.edges.orientation.empty());
  ASSERT_EQ(plain.in_image.lines.size(), 1u);
  EXPECT_LT(angle_diff_deg(plain.in_image.lines[0].theta, 4.0 * kDeg), 1.0);
}

TEST(PhotoDetection, ImagesTooSmallOrTooThinAreNamedOrDetected) {
  // A 1x1 or 3x3 image cannot hold an edge pair 5 px apart: a clear error, not a parameter's.
  for (const int side : {1, 3}) {
    try {
      detect_photo(cv::Mat(side, side, CV_8UC3, cv::Scalar(9, 9, 9)), PhotoOptions{});
      ADD_FAILURE() << side << " px image accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
    }
  }
  // A strip 4000 x 2 px is scaled to the working size with at least one row, and detected.
  cv::Mat strip(2, 4000, CV_8UC3);
  cv::randu(strip, cv::Scalar::all(0), cv::Scalar::all(255));
  const PhotoDetection found = detect_photo(strip, PhotoOptions{});
  EXPECT_GE(found.working_image.rows, 1);
  EXPECT_EQ(found.in_image.width, 4000);
}

TEST(PhotoDetection, CompetitionRule) {
  Line l;
  l.theta = 0;
  l.seg1 = {100, 50};
  l.seg2 = {100, 250};
  EXPECT_TRUE(competition_match(l, {102, 40}, {102, 240}));
  EXPECT_FALSE(competition_match(l, {150, 40}, {150, 240}));   // centre too far
  EXPECT_FALSE(competition_match(l, {100, 50}, {180, 250}));   // angle over 10 deg
  EXPECT_FALSE(competition_match(l, {100, 240}, {100, 260}));  // short truth: its centre is too far
}

TEST(SymmetryEdges, ColourEdgesSeeOutlinesOfEqualBrightness) {
  // Red on green of (nearly) the same grey level: invisible to grey Canny, plain in colour.
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(0, 130, 0));                    // green, grey 76
  cv::rectangle(img, cv::Rect(40, 30, 80, 60), cv::Scalar(0, 0, 255), cv::FILLED);  // red, grey 76
  cv::Mat grey;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  ASSERT_LT(std::abs(grey.at<uint8_t>(60, 80) - grey.at<uint8_t>(5, 5)), 6) << "the test needs equal brightness";
  EdgeParams e{0, 30, 90, false, false};
  EXPECT_EQ(detect_edges(img, e).points.size(), 0u);
  e.colour = true;
  EXPECT_GT(detect_edges(img, e).points.size(), 200u);
}

// ---- line.hpp: the difference of two lines --------------------------------------------------

TEST(LineDifference, SameFormIsPlainSubtraction) {
  const LineDifference d = line_difference(12.0, 10 * kDeg, 10.0, 4 * kDeg);
  EXPECT_NEAR(d.r, 2.0, 1e-12);
  EXPECT_NEAR(d.theta, 6 * kDeg, 1e-12);
}

TEST(LineDifference, WrapsAcrossNinetyDegreesWithRNegated) {
  // (R 30, 89 deg) and (R -30, -89 deg) are 2 degrees apart: -89 deg is the line (30, 91 deg).
  const LineDifference d = line_difference(-30.0, -89 * kDeg, 30.0, 89 * kDeg);
  EXPECT_NEAR(d.r, 0.0, 1e-9);
  EXPECT_NEAR(d.theta, 2 * kDeg, 1e-12);
  const LineDifference back = line_difference(30.0, 89 * kDeg, -30.0, -89 * kDeg);
  EXPECT_NEAR(back.r, 0.0, 1e-9);
  EXPECT_NEAR(back.theta, -2 * kDeg, 1e-12);
  // Not negating R would call them 60 px apart.
  EXPECT_NEAR(line_difference(-25.0, -89 * kDeg, 30.0, 89 * kDeg).r, -5.0, 1e-9);
}

TEST(LineDifference, ThetaStaysWithinAQuarterTurnEitherWay) {
  for (double a = -179.0; a <= 179.0; a += 7.0) {
    for (double b = -89.0; b <= 90.0; b += 11.0) {
      const LineDifference d = line_difference(5.0, a * kDeg, 5.0, b * kDeg);
      EXPECT_GT(d.theta, -M_PI / 2) << a << " " << b;
      EXPECT_LE(d.theta, M_PI / 2 + 1e-12) << a << " " << b;
      // a differs from b by a whole number of half-turns plus d.theta; R flips with odd ones.
      const double half_turns = (a * kDeg - b * kDeg - d.theta) / M_PI;
      EXPECT_NEAR(half_turns, std::round(half_turns), 1e-9);
      const bool odd = std::lround(half_turns) % 2 != 0;
      EXPECT_NEAR(d.r, odd ? -10.0 : 0.0, 1e-9) << a << " " << b;
    }
  }
}

TEST(LineDifference, OfLinesMatchesTheirParameters) {
  Line a, b;
  a.r = -40;
  a.theta = 88 * kDeg;
  b.r = 41;
  b.theta = -87 * kDeg;
  const LineDifference d = line_difference(a, b);
  EXPECT_NEAR(d.r, 40 - 41, 1e-9);  // a taken as (40, -92 deg), 5 deg from b
  EXPECT_NEAR(d.theta, -5 * kDeg, 1e-12);
}

namespace {

// A line of a 640x480 image through `a` and `b` (support segment a..b), with `votes`.
Line line_through(cv::Point2d a, cv::Point2d b, double votes) {
  Line l;
  const cv::Point2d along = (b - a) / cv::norm(b - a);
  l.theta = std::atan2(-along.x, along.y);  // the normal (cos, sin) is the direction turned back a quarter
  l.r = (a - cv::Point2d(319.5, 239.5)).dot(cv::Point2d(std::cos(l.theta), std::sin(l.theta)));
  border_endpoints(l.r, l.theta, 640, 480, &l.end1, &l.end2);
  l.seg1 = a;
  l.seg2 = b;
  l.votes = votes;
  return l;
}

std::vector<double> votes_of(const std::vector<Line>& lines) {
  std::vector<double> v;
  for (const Line& l : lines) v.push_back(l.votes);
  return v;
}

}  // namespace

// Each place once before any twice: a second line of the strongest object (6 px off it, leaning a
// little) and a line hugging it (8 px) wait behind a weaker object's line 60 px away; a line
// straight above the strong object's (an object standing behind it) is a place of its own.
TEST(OneLinePerPlace, APlaceAlreadyOfferedWaitsBehindTheOthers) {
  const std::vector<Line> lines = {
      line_through({300, 200}, {300, 400}, 100),  // the strongest object
      line_through({306, 210}, {302, 390}, 90),   // its second line
      line_through({308, 150}, {308, 330}, 80),   // hugging it, over part of its height
      line_through({300, 40}, {300, 160}, 70),    // above it in the image: behind it on the table
      line_through({360, 220}, {362, 400}, 60),   // a weaker object beside it
  };
  EXPECT_EQ(votes_of(one_line_per_place_first(lines, 12)), (std::vector<double>{100, 70, 60, 90, 80}));
  EXPECT_EQ(votes_of(one_line_per_place_first(lines, 7)), (std::vector<double>{100, 80, 70, 60, 90}))
      << "8 px off is another place at 7 px";
  EXPECT_EQ(votes_of(one_line_per_place_first(lines, 0)), votes_of(lines)) << "0: off";
  EXPECT_TRUE(one_line_per_place_first({}, 12).empty());
  EXPECT_THROW(one_line_per_place_first(lines, std::nan("")), std::invalid_argument);
}

// A line crossing the strongest one is near it only where they cross: it is another place.
TEST(OneLinePerPlace, ALineCrossingAnotherIsAPlaceOfItsOwn) {
  const std::vector<Line> lines = {line_through({300, 200}, {300, 400}, 100), line_through({301, 205}, {301, 395}, 60),
                                   line_through({270, 200}, {330, 400}, 50), line_through({420, 200}, {420, 400}, 40)};
  EXPECT_EQ(votes_of(one_line_per_place_first(lines, 12)), (std::vector<double>{100, 50, 40, 60}));
}

// A line found in part of an image is the same line in the whole image's coordinates: points of the
// region's line, shifted by the region's corner, lie on the whole image's line.
TEST(LineFromRegion, PointsOfTheRegionsLineLieOnTheWholeImagesLine) {
  const cv::Size whole(1280, 960);
  const cv::Rect region(700, 120, 401, 613);
  Line in_region;
  in_region.r = -37.5;
  in_region.theta = 7 * kDeg;
  in_region.seg1 = {180, 40};
  in_region.seg2 = {150, 560};
  const Line mapped = line_from_region(in_region, region, whole);
  EXPECT_DOUBLE_EQ(mapped.theta, in_region.theta);
  const cv::Point2d normal(std::cos(in_region.theta), std::sin(in_region.theta)), along(-normal.y, normal.x);
  const cv::Point2d region_centre((region.width - 1) / 2.0, (region.height - 1) / 2.0);
  const cv::Point2d whole_centre((whole.width - 1) / 2.0, (whole.height - 1) / 2.0);
  for (double t : {-300.0, 0.0, 250.0}) {
    const cv::Point2d p = region_centre + in_region.r * normal + t * along + cv::Point2d(region.x, region.y);
    EXPECT_NEAR((p - whole_centre).dot(normal), mapped.r, 1e-9) << t;
  }
  EXPECT_EQ(mapped.seg1, cv::Point2d(880, 160));
  EXPECT_EQ(mapped.seg2, cv::Point2d(850, 680));
  // Its border ends are the whole image's: on the line, on the border.
  for (const cv::Point2d& end : {mapped.end1, mapped.end2}) {
    EXPECT_NEAR((end - whole_centre).dot(normal), mapped.r, 1e-6);
    EXPECT_TRUE(std::min({end.x, end.y, whole.width - 1 - end.x, whole.height - 1 - end.y}) < 1e-6);
  }
}

// Detected in a crop and mapped back, or detected in the whole image: the same line.
TEST(LineFromRegion, DetectionInACropAgreesWithDetectionInTheWholeImage) {
  cv::Mat image = blank(640, 480, 200);
  const cv::Point centre(420, 250);
  cv::ellipse(image, centre, cv::Size(40, 110), 6, 0, 360, cv::Scalar(40), cv::FILLED);
  cv::rectangle(image, cv::Rect(60, 100, 80, 200), cv::Scalar(90), cv::FILLED);  // another object, outside the crop
  Params p;
  p.theta_min_deg = -20;
  p.theta_max_deg = 20;
  Detector detector(p);
  const Result whole = detector.detect(image);
  const cv::Rect crop(300, 100, 240, 300);
  const Result part = detector.detect(image(crop));
  ASSERT_FALSE(whole.lines.empty());
  ASSERT_FALSE(part.lines.empty());
  const Line mapped = line_from_region(part.lines[0], crop, image.size());
  const Line& same = *std::min_element(whole.lines.begin(), whole.lines.end(), [&](const Line& a, const Line& b) {
    return r_diff(a, mapped.r, mapped.theta) < r_diff(b, mapped.r, mapped.theta);
  });
  EXPECT_LT(r_diff(same, mapped.r, mapped.theta), 0.5);
  EXPECT_LT(angle_diff_deg(same.theta, mapped.theta), 0.2);
  // And it is the ellipse's axis.
  const cv::Point2d c(centre.x - (image.cols - 1) / 2.0, centre.y - (image.rows - 1) / 2.0);
  EXPECT_NEAR(c.dot(cv::Point2d(std::cos(mapped.theta), std::sin(mapped.theta))), mapped.r, 1.5);
}

// The robot's own body left out: the masked edge pixels go with their orientations, the rest keep
// their order; a mask of another size is refused.
TEST(SymmetryEdges, RemoveEdgesDropsTheMaskedPixelsWithTheirOrientations) {
  EdgeSet edges;
  edges.width = 10;
  edges.height = 4;
  for (int x = 0; x < 10; ++x) {
    edges.points.emplace_back(x, 2);
    edges.orientation.push_back(static_cast<int16_t>(x));
    edges.direction.push_back(static_cast<int16_t>(100 + x));
  }
  cv::Mat exclude(4, 10, CV_8UC1, cv::Scalar(0));
  exclude(cv::Rect(0, 0, 5, 4)).setTo(255);
  remove_edges(edges, exclude);
  ASSERT_EQ(edges.points.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(edges.points[i], cv::Point(static_cast<int>(i) + 5, 2));
    EXPECT_EQ(edges.orientation[i], static_cast<int16_t>(i + 5));
    EXPECT_EQ(edges.direction[i], static_cast<int16_t>(i + 105));
  }
  EdgeSet plain = edges_from_mask(cv::Mat::ones(4, 10, CV_8U));  // no orientations
  remove_edges(plain, exclude);
  EXPECT_EQ(plain.points.size(), 20u);
  EXPECT_TRUE(plain.orientation.empty());
  EXPECT_THROW(remove_edges(plain, cv::Mat(5, 10, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
}
