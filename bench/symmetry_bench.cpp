// Google Benchmark suite for the symmetry detector's hot paths on 640x480 indoor-like frames.
// The plain Algorithm 1 loop runs beside the fast voting; setup checks both give the same
// accumulator, so the speed-up is for the same result.
#include <benchmark/benchmark.h>

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

}  // namespace

BENCHMARK(BM_Canny)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteFast)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VoteFastMirror)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VotePlain)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteCornerCutting)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Peaks)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DetectFromEdges)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VoteOrientationRange)->DenseRange(30, 180, 30)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
