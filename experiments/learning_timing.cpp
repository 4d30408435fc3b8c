#include "learning_timing.hpp"

#include <ctime>
#include <fstream>

#include "report.hpp"

namespace nudge::experiments {

RecognitionTiming time_recognition(const std::vector<std::shared_ptr<const learning::ObjectModel>>& objects,
                                   const cv::Mat& image, learning::MatcherKind matcher, int runs) {
  learning::RecognizeParams params;
  params.matcher = matcher;
  learning::Recognizer recognizer(params);
  for (const auto& o : objects) recognizer.add(o);
  recognizer.build_index();  // as the learner does on loading: the timed recognitions only search
  std::vector<double> ms, cpu_ms;
  RecognitionTiming t;
  t.matcher = learning::matcher_name(matcher);
  t.runs = runs;
  for (int i = 0; i < runs; ++i) {
    const std::clock_t start = std::clock();
    const learning::Recognition r = recognizer.recognize(image);
    cpu_ms.push_back(1000.0 * static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC);
    ms.push_back(r.elapsed_ms);
    t.label = r.recognised() ? r.best_score()->name : "";
  }
  t.median_ms = median(ms);
  t.median_cpu_ms = median(cpu_ms);
  return t;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string first;
  in >> first;
  return first.empty() ? "unknown" : first;
}

}  // namespace nudge::experiments
