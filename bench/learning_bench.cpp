// Recognition time against database size (1..100 objects of 12 views each), brute-force matching
// against FLANN's randomised k-d trees (thesis sec. 7.3.4; issue 11). The query's SIFT is detected
// once outside the loop: what is timed is matching, the ratio test and the geometric check.
// Figures: docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <map>

#include "nudge/learning/recognizer.hpp"
#include "nudge/learning/synthetic.hpp"

using namespace nudge::learning;

namespace {

// Objects 0..99, made once (SIFT on 1200 views takes a while).
const std::vector<std::shared_ptr<const ObjectModel>>& objects() {
  static const auto all = synthetic::object_models("object_", 100, 1000);
  return all;
}

// A 640x480 scene holding view 4 of object 0.
const Features& query() {
  static const Features features = [] {
    const cv::Mat face = objects()[0]->views[4].image;
    return detect_features(
        synthetic::place_in_scene(face, synthetic::random_texture({640, 480}, 4242), 10, 0.9, {320, 240}));
  }();
  return features;
}

void BM_Recognize(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  RecognizeParams params;
  params.matcher = state.range(1) ? MatcherKind::Flann : MatcherKind::BruteForce;
  Recognizer recognizer(params);
  for (int i = 0; i < n; ++i) recognizer.add(objects()[i]);
  const Features& q = query();
  int recognised = 0;
  for (auto _ : state) {
    const Recognition r = recognizer.recognize(q);
    recognised += r.recognised() && r.best_score()->name == "object_0";
    benchmark::DoNotOptimize(r);
  }
  state.counters["correct"] = static_cast<double>(recognised) / state.iterations();
  state.counters["query_features"] = q.size();
  state.SetLabel(matcher_name(params.matcher));
}

void Sizes(benchmark::internal::Benchmark* b) {
  for (int kind : {0, 1})
    for (int n : {1, 3, 10, 30, 100}) b->Args({n, kind});
  b->ArgNames({"objects", "flann"})->Unit(benchmark::kMillisecond);
}

}  // namespace

BENCHMARK(BM_Recognize)->Apply(Sizes);
BENCHMARK_MAIN();
