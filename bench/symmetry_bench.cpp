// Google Benchmark suite for the symmetry detector's hot paths on 640x480 indoor-like frames.
// The plain Algorithm 1 loop runs beside the fast voting; setup checks both give the same
// accumulator, so the speed-up is for the same result.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <filesystem>

#include "nudge/symmetry/corner_cutting.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/synthetic.hpp"

namespace sym = nudge::symmetry;

namespace {

const sym::EdgeSet& frame_edges() {
  static const sym::EdgeSet edges =
      sym::detect_edges(sym::synthetic::indoor_scene(3, 640, 480, 4), sym::EdgeParams{1.0, 30, 90, false});
  return edges;
}

sym::Params table_params(int threads = 1) {
  sym::Params p;
  p.dmin = 25;
  p.dmax = 250;
  p.num_lines = 5;
  p.threads = threads;
  return p;
}

void BM_Canny(benchmark::State& state) {
  const cv::Mat frame = sym::synthetic::indoor_scene(3, 640, 480, 4);
  for (auto _ : state) benchmark::DoNotOptimize(sym::detect_edges(frame, sym::EdgeParams{1.0, 30, 90, false}));
}

void BM_VoteFast(benchmark::State& state) {
  sym::Detector d(table_params(static_cast<int>(state.range(0))));
  const auto& edges = frame_edges();
  if (cv::countNonZero(d.vote(edges).votes[0] != sym::reference_vote(edges, table_params()).votes[0]) != 0) {
    state.SkipWithError("fast accumulator differs from the plain one");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(d.vote(edges));
  state.counters["edges"] = static_cast<double>(edges.points.size());
}

// Mirror-consistent pairs (Params::mirror_tolerance_deg = 15): the same frame with orientations.
void BM_VoteFastMirror(benchmark::State& state) {
  static const sym::EdgeSet edges = [] {
    sym::EdgeParams e{1.0, 30, 90, false};
    e.gradients = true;
    return sym::detect_edges(sym::synthetic::indoor_scene(3, 640, 480, 4), e);
  }();
  sym::Params p = table_params();
  p.mirror_tolerance_deg = 15;
  sym::Detector d(p);
  if (cv::countNonZero(d.vote(edges).votes[0] != sym::reference_vote(edges, p).votes[0]) != 0) {
    state.SkipWithError("fast accumulator differs from the plain one");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(d.vote(edges));
  state.counters["edges"] = static_cast<double>(edges.points.size());
}

void BM_VotePlain(benchmark::State& state) {
  const auto& edges = frame_edges();
  for (auto _ : state) benchmark::DoNotOptimize(sym::reference_vote(edges, table_params()));
}

// The thesis author's published shortcuts (corner_cutting.hpp): casts only some of the votes.
void BM_VoteCornerCutting(benchmark::State& state) {
  const auto& edges = frame_edges();
  sym::CornerCuttingVoter voter;
  const double all = cv::sum(sym::reference_vote(edges, table_params()).votes[0])[0];
  const double cast = cv::sum(voter.vote(edges, table_params()).votes[0])[0];
  for (auto _ : state) benchmark::DoNotOptimize(voter.vote(edges, table_params()));
  state.counters["votes_cast_fraction"] = cast / all;
}

void BM_Peaks(benchmark::State& state) {
  sym::Detector d(table_params());
  const auto& edges = frame_edges();
  const sym::Accumulator acc = d.vote(edges);
  for (auto _ : state) benchmark::DoNotOptimize(d.find_peaks(acc, 640, 480));
}

void BM_DetectFromEdges(benchmark::State& state) {
  sym::Detector d(table_params());
  const auto& edges = frame_edges();
  for (auto _ : state) benchmark::DoNotOptimize(d.detect(edges));
}

void BM_VoteOrientationRange(benchmark::State& state) {
  sym::Params p = table_params();
  p.theta_min_deg = -state.range(0) / 2.0;
  p.theta_max_deg = state.range(0) / 2.0;
  sym::Detector d(p);
  const auto& edges = frame_edges();
  for (auto _ : state) benchmark::DoNotOptimize(d.vote(edges));
}

// Dense real frames (issue 14): opencv-doc's pictures at 640x480 with orientations, mirror rule
// 15 deg. Variants: 0 today's exact voting (every pair of a row), 1 the default (windowed where it
// pays: the portable loops), 2 / 3 the same two with the portable loops, 4 the thesis author's
// shortcut loop (a baseline, rule off). docs/results/mirror_voting.md has the same in one run.
const std::array<const char*, 4> kDenseFrames = {"building.jpg", "home.jpg", "box_in_scene.png", "fruits.jpg"};

const sym::EdgeSet* dense_edges(size_t index) {
  static std::array<std::unique_ptr<sym::EdgeSet>, 4> cache;
  if (!cache[index]) {
    const std::string path = std::string("/usr/share/doc/opencv-doc/examples/data/") + kDenseFrames[index];
    if (!std::filesystem::exists(path)) return nullptr;
    cv::Mat frame;
    cv::resize(cv::imread(path, cv::IMREAD_COLOR), frame, {640, 480}, 0, 0, cv::INTER_AREA);
    sym::EdgeParams e{1.0, 30, 90, false};
    e.gradients = true;
    cache[index] = std::make_unique<sym::EdgeSet>(sym::detect_edges(frame, e));
  }
  return cache[index].get();
}

void BM_VoteMirrorDense(benchmark::State& state) {
  const size_t frame = static_cast<size_t>(state.range(0));
  const int variant = static_cast<int>(state.range(1));
  const sym::EdgeSet* edges = dense_edges(frame);
  if (!edges) {
    state.SkipWithError("opencv-doc's pictures are not installed");
    return;
  }
  sym::Params p = table_params();
  p.mirror_tolerance_deg = 15;
  p.mirror_sorted_rows = variant == 1 || variant == 3;
  p.vector_kernels = variant < 2;
  state.SetLabel(std::string(kDenseFrames[frame]) + (variant == 4 ? " author's loop" : ""));
  state.counters["edges"] = static_cast<double>(edges->points.size());
  if (variant == 4) {
    sym::CornerCuttingVoter author;
    for (auto _ : state) benchmark::DoNotOptimize(author.vote(*edges, table_params()));
    return;
  }
  sym::Detector d(p);
  static std::array<std::unique_ptr<cv::Mat>, 4> plain;  // the plain loop's accumulator, once per frame
  if (!plain[frame]) plain[frame] = std::make_unique<cv::Mat>(sym::reference_vote(*edges, p).votes[0]);
  if (cv::countNonZero(d.vote(*edges).votes[0] != *plain[frame]) != 0) {
    state.SkipWithError("accumulator differs from the plain one");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(d.vote(*edges));
}

}  // namespace

BENCHMARK(BM_Canny)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteFast)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VoteFastMirror)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VotePlain)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteCornerCutting)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Peaks)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DetectFromEdges)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteOrientationRange)->DenseRange(30, 180, 30)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteMirrorDense)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2, 3, 4}})
    ->ArgNames({"frame", "variant"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
