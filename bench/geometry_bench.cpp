// Google Benchmark suite for segmentation and stereo geometry: contour segmentation per symmetry
// line on a 640x480 indoor-like frame (thesis Table 4.1 conditions), and triangulating the 25
// left x right pairings of one stereo frame with 5 lines per image (thesis sec. 4.3.4).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cmath>

#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/table_texture.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/synthetic.hpp"

namespace sym = nudge::symmetry;
namespace seg = nudge::segmentation;
namespace geo = nudge::geometry;

namespace {

struct Frame {
  sym::EdgeSet edges;
  std::vector<sym::Line> lines;
};

// Frame 3 of Table 3.1's set; 5 lines, Dmin 25, Dmax 250, full 180 degrees.
const Frame& frame() {
  static const Frame f = [] {
    Frame out;
    out.edges = sym::detect_edges(sym::synthetic::indoor_scene(3, 640, 480, 4), sym::EdgeParams{1.0, 30, 90, false});
    sym::Params p;
    p.dmin = 25;
    p.dmax = 250;
    p.num_lines = 5;
    out.lines = sym::Detector(p).detect(out.edges).lines;
    return out;
  }();
  return f;
}

// Segments each detected line in turn; time per line. MAXw = the image width (the thesis' timing
// trials) or Dmax (its usual setting).
void BM_SegmentPerLine(benchmark::State& state) {
  seg::SegmentParams params;
  params.max_width = static_cast<double>(state.range(0));
  const seg::Segmenter segmenter(params);
  const Frame& f = frame();
  if (f.lines.empty()) {
    state.SkipWithError("no symmetry lines in the frame");
    return;
  }
  size_t next = 0;
  long long pairs = 0;
  for (const auto& line : f.lines) pairs += segmenter.sept(f.edges, line).num_pairs;
  for (auto _ : state) {
    benchmark::DoNotOptimize(segmenter.segment(f.edges, f.lines[next]));
    next = (next + 1) % f.lines.size();
  }
  state.counters["edges"] = static_cast<double>(f.edges.points.size());
  state.counters["edge_pairs"] = static_cast<double>(pairs) / f.lines.size();
}

void BM_Sept(benchmark::State& state) {
  seg::SegmentParams params;
  params.max_width = 640;
  const seg::Segmenter segmenter(params);
  const Frame& f = frame();
  for (auto _ : state) benchmark::DoNotOptimize(segmenter.sept(f.edges, f.lines.front()));
}

// A verged rig (0.25 m baseline, 15 deg vergence, cameras 0.45 m above the table looking 30 deg
// down) and five lines per image, like a detector's top five: four upright objects and a stray line.
// Ghost pairings of two different objects' lines are part of the work, as on real frames.
struct Stereo {
  geo::StereoRig rig;
  geo::Plane table;
  std::vector<sym::Line> left, right;
};

sym::Line line_through(const geo::Camera& camera, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector2d pa = camera.project(a), pb = camera.project(b);
  const Eigen::Vector2d dir = (pb - pa).normalized(), normal(-dir.y(), dir.x());
  sym::Line line;
  line.theta = std::atan2(normal.y(), normal.x());
  Eigen::Vector2d n = normal;
  if (line.theta > M_PI / 2) line.theta -= M_PI, n = -n;
  if (line.theta <= -M_PI / 2) line.theta += M_PI, n = -n;
  line.r = n.dot(pa - Eigen::Vector2d(0.5 * (camera.width - 1), 0.5 * (camera.height - 1)));
  line.seg1 = {pa.x(), pa.y()};
  line.seg2 = {pb.x(), pb.y()};
  sym::border_endpoints(line.r, line.theta, camera.width, camera.height, &line.end1, &line.end2);
  return line;
}

const Stereo& stereo() {
  static const Stereo s = [] {
    Stereo out;
    for (geo::Camera* c : {&out.rig.left, &out.rig.right}) {
      c->K << 620, 0, 319.5, 0, 620, 239.5, 0, 0, 1;
      c->distortion = {-0.15, 0.07, 0.001, -0.001, 0};
    }
    const Eigen::Matrix3d right_in_left =
        Eigen::AngleAxisd(-15 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    out.rig.R = right_in_left.transpose();
    out.rig.T = -out.rig.R * Eigen::Vector3d(0.25, 0, 0);
    const Eigen::Vector3d up(0, -std::cos(M_PI / 6), -std::sin(M_PI / 6));
    const Eigen::Vector3d forward(0, -std::sin(M_PI / 6), std::cos(M_PI / 6));
    out.table.normal = out.rig.R * up;
    out.table.offset = -out.table.normal.dot(out.rig.left_to_right(-0.45 * up + 0.6 * forward));
    const double lateral[] = {-0.1, 0.0, 0.08, 0.15}, distance[] = {0.55, 0.7, 0.6, 0.75};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d base = lateral[k] * Eigen::Vector3d::UnitX() + distance[k] * forward - 0.45 * up;
      const Eigen::Vector3d top = base + 0.15 * up;
      out.left.push_back(line_through(out.rig.left, base, top));
      out.right.push_back(line_through(out.rig.right, out.rig.left_to_right(base), out.rig.left_to_right(top)));
    }
    sym::Line stray;
    stray.r = 200;
    stray.theta = 0.1;
    sym::border_endpoints(stray.r, stray.theta, 640, 480, &stray.end1, &stray.end2);
    stray.seg1 = stray.end1;
    stray.seg2 = stray.end2;
    out.left.push_back(stray);
    out.right.push_back(stray);
    return out;
  }();
  return s;
}

void BM_Triangulate25Pairings(benchmark::State& state) {
  const Stereo& s = stereo();
  geo::TriangulationParams params;
  params.plane_samples = static_cast<int>(state.range(0));
  int valid = 0;
  for (auto _ : state) {
    const auto result = geo::triangulate_pairings(s.rig, s.left, s.right, &s.table, geo::AxisFilter{}, params);
    valid = static_cast<int>(result.axes.size());
    benchmark::DoNotOptimize(result);
  }
  state.counters["valid_axes"] = valid;
}

// The table's texture mask of one 640x480 camera image against the other's (the symmetry
// service's --table-texture-calibration, per image): warp, 9 shifted window comparisons, erosion.
// The images: the same synthetic indoor frame, so that most of it agrees somewhere.
void BM_TableTextureMask(benchmark::State& state) {
  const Stereo& s = stereo();
  const geo::PlaneWarp warp = geo::plane_warp(s.rig, geo::Side::Right, s.table);
  const cv::Mat image = sym::synthetic::indoor_scene(3, 640, 480, 4);
  int table_px = 0;
  for (auto _ : state) {
    const cv::Mat mask = geo::table_texture_mask(image, image, warp);
    table_px = cv::countNonZero(mask);
    benchmark::DoNotOptimize(mask.data);
  }
  state.counters["table_px"] = table_px;
}

// Making the warp (once per calibration, at the service's start): every pixel's ray through both lenses.
void BM_PlaneWarp(benchmark::State& state) {
  const Stereo& s = stereo();
  for (auto _ : state) benchmark::DoNotOptimize(geo::plane_warp(s.rig, geo::Side::Right, s.table).map_x.data);
}

}  // namespace

BENCHMARK(BM_SegmentPerLine)->Arg(640)->Arg(250)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sept)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Triangulate25Pairings)->Arg(0)->Arg(32)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TableTextureMask)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlaneWarp)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
