// Recognition time against database size (issue 11; thesis sec. 7.3.4): each matcher (per-object
// brute force, per-object FLANN, one FLANN index over the database) at 1, 10, 30 and 100 objects,
// CPU time of recognising one 640x480 scene (SIFT of the scene excluded: the same for every
// matcher), median of --runs; and per row whether the right object was found in each query scene
// and, for a scene of an object not in the database, nothing was.
//   nudge-exp-recognition-scaling [--runs 5] [--name recognition_scaling]
// Evaluation data fixed in advance, apart from what the matchers were tuned on (bench/learning_bench
// objects 1000..1099, the unit tests' 10..12): objects of seeds 5000..5099, scenes of seeds 5500..,
// the unknown object seed 5999. Writes docs/results/NAME.{json,md}.
#include <algorithm>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/learning/recognizer.hpp"
#include "nudge/learning/synthetic.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace learning = nudge::learning;

namespace {

const std::vector<int> kSizes = {1, 10, 30, 100};
const std::vector<learning::MatcherKind> kMatchers = {learning::MatcherKind::BruteForce, learning::MatcherKind::Flann,
                                                      learning::MatcherKind::SharedFlann};
constexpr uint64_t kObjectSeed = 5000, kSceneSeed = 5500, kUnknownSeed = 5999;

std::string object_name(int i) { return "object_" + std::to_string(i); }

double cpu_ms_since(std::clock_t start) { return 1000.0 * static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; }

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string first;
  in >> first;
  return first.empty() ? "unknown" : first;
}

// A query: a training view of one object (turned and scaled) in a random scene, and the answer.
struct Query {
  std::string truth;  // empty: no object of the database
  learning::Features features;
};

Query make_query(const learning::ObjectModel& object, int view, double angle, double scale, uint64_t scene_seed,
                 const std::string& truth) {
  const cv::Mat scene = learning::synthetic::place_in_scene(
      object.views[view].image, learning::synthetic::random_texture({640, 480}, scene_seed), angle, scale, {320, 240});
  return {truth, learning::detect_features(scene)};
}

// The queries for a database of the first n objects: its first, middle and last object, and the
// unknown object.
std::vector<const Query*> queries_for(int n, const std::vector<Query>& known, const std::vector<int>& known_index,
                                      const Query& unknown) {
  std::vector<const Query*> out;
  for (int i : {0, n / 2, n - 1}) {
    for (size_t q = 0; q < known.size(); ++q)
      if (known_index[q] == i && std::find(out.begin(), out.end(), &known[q]) == out.end()) out.push_back(&known[q]);
  }
  out.push_back(&unknown);
  return out;
}

struct Row {
  learning::MatcherKind matcher;
  int objects = 0, descriptors = 0;
  double index_build_cpu_ms = 0;  // building the matcher indexes for the whole database
  double median_cpu_ms = 0;
  std::vector<double> cpu_ms;
  int queries = 0, correct = 0;
  int verified_on_first = 0;  // verified matches of the right object on the timed query
  std::vector<std::string> answers;  // per query: "truth -> answer (verified matches)"
};

bool answered_right(const learning::Recognition& r, const Query& q) {
  if (q.truth.empty()) return !r.recognised();
  return r.recognised() && r.best_score()->name == q.truth;
}

Row measure(learning::MatcherKind kind, const std::vector<std::shared_ptr<const learning::ObjectModel>>& objects, int n,
            const std::vector<const Query*>& queries, int runs) {
  Row row;
  row.matcher = kind;
  row.objects = n;
  learning::RecognizeParams params;
  params.matcher = kind;
  learning::Recognizer recognizer(params);
  const std::clock_t build_start = std::clock();
  for (int i = 0; i < n; ++i) {
    recognizer.add(objects[i]);
    row.descriptors += objects[i]->descriptor_count();
  }
  recognizer.build_index();
  row.index_build_cpu_ms = cpu_ms_since(build_start);
  for (const Query* q : queries) {
    const learning::Recognition r = recognizer.recognize(q->features);
    ++row.queries;
    row.correct += answered_right(r, *q);
    row.answers.push_back((q->truth.empty() ? std::string("unknown") : q->truth) + " -> " +
                          (r.recognised() ? r.best_score()->name + " (" + std::to_string(r.best_score()->verified_matches) + ")"
                                          : std::string("nothing")));
  }
  // The timed query: the first object's scene (in every database).
  for (int i = 0; i < runs; ++i) {
    const std::clock_t start = std::clock();
    const learning::Recognition r = recognizer.recognize(queries[0]->features);
    row.cpu_ms.push_back(cpu_ms_since(start));
    if (i == 0) row.verified_on_first = r.recognised() ? r.best_score()->verified_matches : 0;
  }
  row.median_cpu_ms = median(row.cpu_ms);
  return row;
}

std::string fixed(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  std::string name = "recognition_scaling";
  int runs = 5;
  Flags flags("nudge-exp-recognition-scaling", "Recognition time and correctness against database size per matcher.");
  flags.add_int("runs", &runs, "timed recognitions per matcher and database size (median)");
  flags.add_string("name", &name, "result name");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (runs < 1) throw FlagError("--runs must be >= 1");
    const int largest = kSizes.back();
    std::vector<std::shared_ptr<const learning::ObjectModel>> objects;
    for (int i = 0; i < largest; ++i)
      objects.push_back(std::make_shared<const learning::ObjectModel>(
          learning::synthetic::object_model(object_name(i), kObjectSeed + i)));
    // Scenes of objects 0, n/2 and n-1 for every n, each of another view, angle and scale.
    std::vector<Query> known;
    std::vector<int> known_index;
    uint64_t scene_seed = kSceneSeed;
    for (int n : kSizes) {
      for (int i : {0, n / 2, n - 1}) {
        if (std::find(known_index.begin(), known_index.end(), i) != known_index.end()) continue;
        const int view = static_cast<int>(scene_seed % 12);
        known.push_back(make_query(*objects[i], view, -30.0 + 7.0 * (scene_seed % 9), 0.8 + 0.1 * (scene_seed % 4),
                                   scene_seed, object_name(i)));
        known_index.push_back(i);
        ++scene_seed;
      }
    }
    const auto unknown_object = learning::synthetic::object_model("unknown", kUnknownSeed);
    const Query unknown = make_query(unknown_object, 3, 12, 1.0, scene_seed, "");

    std::vector<Row> rows;
    nudge::Progress progress("nudge-exp-recognition-scaling", static_cast<int>(kSizes.size() * kMatchers.size()));
    for (int n : kSizes) {
      const auto queries = queries_for(n, known, known_index, unknown);
      for (learning::MatcherKind kind : kMatchers) {
        progress.step(std::string(learning::matcher_name(kind)) + " at " + std::to_string(n) + " objects");
        rows.push_back(measure(kind, objects, n, queries, runs));
        const Row& r = rows.back();
        std::ostringstream line;
        line << learning::matcher_name(kind) << " at " << n << " objects: " << r.median_cpu_ms << " ms CPU, "
             << r.correct << "/" << r.queries << " right";
        progress.note(line.str());
      }
    }
    progress.clear_status();  // the result files' "wrote" lines follow on stderr

    const learning::RecognizeParams defaults;
    auto row_of = [&](learning::MatcherKind kind, int n) -> const Row& {
      for (const Row& r : rows)
        if (r.matcher == kind && r.objects == n) return r;
      throw std::logic_error("no row");
    };
    const Row& chosen = row_of(defaults.matcher, largest);
    const Row& before = row_of(learning::MatcherKind::Flann, largest);  // the default before issue 11's index
    bool all_right = true;
    for (const Row& r : rows) all_right = all_right && r.correct == r.queries;

    JsonWriter j;
    j.begin_object();
    j.field("machine", machine_description()).field("date", today()).field("load_average", load_average());
    j.field("runs", runs).field("query_features", static_cast<int>(known[0].features.size()));
    j.field("default_matcher", learning::matcher_name(defaults.matcher));
    j.field("shared_neighbours", defaults.shared_neighbours).field("shared_checks", defaults.shared_checks);
    j.field("recognition_ms_at_100_objects", chosen.median_cpu_ms);
    j.field("speedup_at_100_objects_vs_per_object_flann", before.median_cpu_ms / chosen.median_cpu_ms);
    j.field("all_correct", all_right);
    j.key("rows").begin_array();
    for (const Row& r : rows) {
      j.begin_object().field("matcher", learning::matcher_name(r.matcher)).field("objects", r.objects);
      j.field("descriptors", r.descriptors).field("recognition_cpu_ms", r.median_cpu_ms);
      j.key("recognition_cpu_ms_runs").begin_array();
      for (double v : r.cpu_ms) j.value(v);
      j.end_array();
      j.field("index_build_cpu_ms", r.index_build_cpu_ms);
      j.field("queries", r.queries).field("correct", r.correct).field("verified_matches_first_query", r.verified_on_first);
      j.key("answers").begin_array();
      for (const std::string& a : r.answers) j.value(a);
      j.end_array();
      j.end_object();
    }
    j.end_array();
    j.end_object();
    write_result(name + ".json", j.str() + "\n");

    std::ostringstream md;
    md << "# Recognition time against database size (issue 11)\n\n"
       << "`nudge-exp-recognition-scaling`: databases of the first 1, 10, 30 and 100 of 100 synthetic textured "
          "objects (12 turntable views each, seeds " << kObjectSeed << "..." << kObjectSeed + largest - 1
       << "), one 640x480 scene of object 0 (" << known[0].features.size()
       << " SIFT features) recognised " << runs << " times per matcher and size: median CPU time of matching, "
          "ratio test and geometric check (the scene's SIFT, the same for all, excluded). *Right* counts the "
          "scenes of the database's first, middle and last object recognised as that object, and a scene of "
          "an object not in the database recognised as nothing. *Index build*: adding the database and "
          "building the matcher indexes.\n\n"
       << "| matcher | objects | descriptors | recognition CPU ms | right | verified matches (object 0) | index build CPU ms | answers: truth -> recognised (verified matches) |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      md << "| " << learning::matcher_name(r.matcher) << " | " << r.objects << " | " << r.descriptors << " | "
         << fixed(r.median_cpu_ms) << " | " << r.correct << "/" << r.queries << " | " << r.verified_on_first << " | "
         << fixed(r.index_build_cpu_ms, 0) << " | ";
      for (size_t a = 0; a < r.answers.size(); ++a) md << (a ? "; " : "") << r.answers[a];
      md << " |\n";
    }
    md << "\nThe default matcher is `" << learning::matcher_name(defaults.matcher) << "` ("
       << defaults.shared_neighbours << " neighbours per query descriptor over the database, "
       << defaults.shared_checks << " k-d tree checks): `recognition_ms_at_100_objects` = "
       << fixed(chosen.median_cpu_ms) << " ms CPU, " << fixed(before.median_cpu_ms / chosen.median_cpu_ms)
       << "x faster than per-object FLANN (the default before). "
       << (all_right ? "Every matcher answered every scene right at every size."
                     : "Not every answer was right: see the table.")
       << "\n\nCPU time, not wall time: the machine is shared (load average " << load_average()
       << " when it finished). " << machine_description() << ", " << today() << ".\n";
    write_result(name + ".md", md.str());
    std::ostringstream summary;
    summary << rows.size() << " matcher/size pairs, " << (all_right ? "every answer right" : "NOT every answer right")
            << ", " << learning::matcher_name(defaults.matcher) << " at " << largest << " objects "
            << fixed(chosen.median_cpu_ms) << " ms CPU";
    progress.finish(summary.str());
    return all_right ? 0 : 1;
  } catch (const FlagError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-recognition-scaling: " << e.what() << "\n";
    return 1;
  }
}
