// The learner service's handlers in-process (memq://): training views in, LEARNED out, the object
// in the database; RECOGNIZE_REQUEST in, RECOGNITION out with a match picture; bad input (an
// undecodable image, views never committed, an unknown key) reported naming it while the service
// keeps answering.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <filesystem>
#include <future>
#include <memory>

#include "learner/handlers.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/latest.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/learn_result_t.hpp"
#include "nudge/learning/database.hpp"
#include "nudge/learning/synthetic.hpp"
#include "nudge/recognition_t.hpp"

namespace fs = std::filesystem;
namespace syn = nudge::learning::synthetic;
namespace channel = nudge::bus::channel;
using nudge::bus::Latest;

namespace {

const cv::Rect kBox(150, 50, 100, 200);
constexpr int64_t kSecond = 1000000;

std::vector<nudge::learning::TrainingImage> turntable(uint64_t seed) {
  return syn::turntable_views(syn::random_texture({400, 200}, seed), syn::random_texture({400, 300}, 500), kBox, 12);
}

nudge::learn_view_t view_message(const std::string& run, const std::string& key, int index,
                                 const nudge::learning::TrainingImage& view, int64_t utime) {
  nudge::learn_view_t msg{};
  msg.utime = utime;
  msg.run_id = run;
  msg.object_key = key;
  msg.view_index = index;
  msg.wrist_angle = view.wrist_angle;
  msg.box[0] = view.box.x;
  msg.box[1] = view.box.y;
  msg.box[2] = view.box.width;
  msg.box[3] = view.box.height;
  msg.image = nudge::bus::to_message(view.image, index % 2 ? nudge::image_t::FORMAT_PNG : nudge::image_t::FORMAT_BGR8,
                                     utime, index, "right");
  return msg;
}

nudge::learn_commit_t commit_message(const std::string& run, const std::string& key, const std::string& name,
                                     int views, int64_t utime, int64_t seq) {
  nudge::learn_commit_t msg{};
  msg.utime = utime;
  msg.seq = seq;
  msg.run_id = run;
  msg.object_key = key;
  msg.object_name = name;
  msg.num_views = views;
  msg.height = 0.2;
  msg.radius = 0.03;
  return msg;
}

nudge::recognize_request_t request(const cv::Mat& image, int64_t seq, bool picture) {
  nudge::recognize_request_t msg{};
  msg.utime = 9000 * kSecond;
  msg.seq = seq;
  msg.want_match_picture = picture;
  msg.image = nudge::bus::to_message(image, nudge::image_t::FORMAT_PNG, msg.utime, seq, "right");
  return msg;
}

// A scene the robot never saw with view `view` of turntable object `seed` in it.
cv::Mat scene_with(uint64_t seed, int view) {
  return syn::place_in_scene(turntable(seed)[view].image(kBox), syn::random_texture({640, 480}, 900), 10, 0.9,
                             {350, 240});
}

// A learner on a bus of the test's own, with the test's end subscribed to its answers.
struct InProcess {
  explicit InProcess(const std::string& db)
      : service("learner", "in-process test"),
        started((service.start(bus), true)),
        handlers(std::make_unique<nudge::learner_service::Handlers>(service, options(db))),
        probe(bus, probe_counters),
        learned(probe, channel::LEARNED),
        recognition(probe, channel::RECOGNITION) {}
  static nudge::learner_service::Options options(const std::string& db) {
    nudge::learner_service::Options o;
    o.db_dir = db;
    o.view_expiry_s = 60;
    return o;
  }
  void teach(const std::string& run, const std::string& key, uint64_t seed, int64_t t0) {
    const auto views = turntable(seed);
    for (int i = 0; i < static_cast<int>(views.size()); ++i) {
      const auto msg = view_message(run, key, i, views[i], t0 + i * kSecond);
      bus.publish(channel::LEARN_VIEW, &msg);
    }
  }
  // Commits the gathered views and waits for the worker: the LEARNED answer.
  nudge::learn_result_t commit(const std::string& run, const std::string& key, int views, int64_t utime, int64_t seq) {
    const auto msg = commit_message(run, key, key, views, utime, seq);
    bus.publish(channel::LEARN_COMMIT, &msg);
    service.handle_pending();
    handlers->finish_learning();
    service.handle_pending();
    return learned.get();
  }
  lcm::LCM bus{"memq://"};
  nudge::bus::Service service;
  bool started;
  std::unique_ptr<nudge::learner_service::Handlers> handlers;
  nudge::bus::Counters probe_counters;
  nudge::bus::Subscriptions probe;
  Latest<nudge::learn_result_t> learned;
  Latest<nudge::recognition_t> recognition;
};

std::string fresh_db(const std::string& name) {
  const std::string dir = fs::temp_directory_path().string() + "/nudge_learner_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST(LearnerHandlers, LearnsStoresAndRecognisesWithAMatchPicture) {
  const std::string db = fresh_db("learn");
  InProcess run(db);
  EXPECT_EQ(run.handlers->known_objects(), 0);
  run.teach("run_1", "attempt_01", 11, 100 * kSecond);
  const auto commit = commit_message("run_1", "attempt_01", "cereal", 12, 120 * kSecond, 7);
  run.bus.publish(channel::LEARN_COMMIT, &commit);
  run.service.handle_pending();
  run.handlers->finish_learning();  // the worker thread learns; LEARNED comes from poll()
  run.service.handle_pending();
  ASSERT_TRUE(run.learned.has());
  const nudge::learn_result_t result = run.learned.get();
  EXPECT_TRUE(result.ok) << result.reason;
  EXPECT_EQ(result.seq, 7);
  EXPECT_EQ(result.object_name, "cereal");
  EXPECT_EQ(result.views_used, 12);
  EXPECT_GT(result.descriptors, 500);
  EXPECT_GT(result.descriptors_pruned, 500);  // the static scene around the object
  EXPECT_TRUE(fs::exists(db + "/cereal/object.json"));
  EXPECT_EQ(run.handlers->known_objects(), 1);
  EXPECT_EQ(run.handlers->pending_objects(), 0);

  const auto ask = request(scene_with(11, 5), 8, true);
  run.bus.publish(channel::RECOGNIZE_REQUEST, &ask);
  run.service.handle_pending();
  ASSERT_TRUE(run.recognition.has());
  const nudge::recognition_t answer = run.recognition.get();
  EXPECT_EQ(answer.seq, 8);
  EXPECT_EQ(answer.label, "cereal") << answer.reason;
  EXPECT_NEAR(answer.best_view, 5, 1);
  EXPECT_EQ(answer.learned_utime, 120 * kSecond);
  ASSERT_EQ(answer.num_objects, 1);
  EXPECT_EQ(answer.names[0], "cereal");
  EXPECT_GE(answer.matches[0], 15);
  EXPECT_GT(answer.elapsed_ms, 0);
  ASSERT_GT(answer.match_picture.size, 0);
  const cv::Mat picture = nudge::bus::to_mat(answer.match_picture);
  EXPECT_EQ(picture.rows, 480 + 300);  // the scene above the training view
  EXPECT_EQ(run.service.counters().errors, 0);

  // Another learner on the same folder knows the object from the start.
  InProcess again(db);
  EXPECT_EQ(again.handlers->known_objects(), 1);
  const auto plain = request(scene_with(11, 5), 9, false);
  again.bus.publish(channel::RECOGNIZE_REQUEST, &plain);
  again.service.handle_pending();
  ASSERT_TRUE(again.recognition.has());
  EXPECT_EQ(again.recognition.get().label, "cereal");
  EXPECT_EQ(again.recognition.get().match_picture.size, 0) << "no picture unless asked for";
  fs::remove_all(db);
}

// The scene still (learn_view_t::KIND_SCENE): the views' scene without the object held prunes what
// stands in place behind it; one of another size is left out, an unknown kind refused by name.
TEST(LearnerHandlers, TheSceneStillPrunesWhatStandsBehindTheObject) {
  const std::string db = fresh_db("scene");
  InProcess run(db);
  auto learn = [&](const std::string& key, const cv::Mat& scene, int8_t kind, int64_t t0, int64_t seq) {
    run.teach("run_5", key, 13, t0);
    if (!scene.empty()) {
      nudge::learning::TrainingImage still;
      still.image = scene;
      auto msg = view_message("run_5", key, 0, still, t0 + 20 * kSecond);
      msg.view_index = -1;
      msg.kind = kind;
      run.bus.publish(channel::LEARN_VIEW, &msg);
    }
    return run.commit("run_5", key, 12, t0 + 21 * kSecond, seq);
  };
  const cv::Mat behind = syn::random_texture({400, 300}, 500);  // turntable()'s scene
  const auto plain = learn("plain", {}, 0, 100 * kSecond, 1);
  const auto pruned = learn("pruned", behind, nudge::learn_view_t::KIND_SCENE, 200 * kSecond, 2);
  const auto small = learn("small", syn::random_texture({200, 150}, 500), nudge::learn_view_t::KIND_SCENE, 300 * kSecond, 3);
  ASSERT_TRUE(plain.ok && pruned.ok && small.ok) << plain.reason << pruned.reason << small.reason;
  EXPECT_LT(pruned.descriptors, plain.descriptors);  // the scene the generous box still held
  EXPECT_EQ(pruned.descriptors + pruned.descriptors_pruned, plain.descriptors + plain.descriptors_pruned);
  EXPECT_EQ(small.descriptors, plain.descriptors) << "a scene still of another size is left out";
  const int errors = run.service.counters().errors;
  const auto odd = learn("odd", behind, 7, 400 * kSecond, 4);
  EXPECT_TRUE(odd.ok) << "the views still serve";
  EXPECT_EQ(odd.descriptors, plain.descriptors);
  EXPECT_EQ(run.service.counters().errors, errors + 1) << "the unknown kind is reported";
  fs::remove_all(db);
}

// The supervisor's standing view comes with the object's mask: only what lies inside is learned,
// the mask is stored with the view, and a mask that does not fit its view is refused by name.
TEST(LearnerHandlers, AStandingViewsMaskKeepsWhatLiesOnTheObjectAndABadOneIsRefused) {
  const std::string db = fresh_db("mask");
  InProcess run(db);
  const cv::Rect object(170, 80, 60, 150);
  cv::Mat mask(300, 400, CV_8UC1, cv::Scalar(0));
  mask(object).setTo(255);
  nudge::learning::TrainingImage standing;
  standing.image = syn::random_texture({400, 300}, 600);
  standing.box = object;
  auto learn = [&](const std::string& key, const cv::Mat& view_mask, int64_t t0, int64_t seq) {
    run.teach("run_6", key, 14, t0);
    auto msg = view_message("run_6", key, 12, standing, t0 + 13 * kSecond);
    if (!view_mask.empty()) msg.mask = nudge::bus::to_message(view_mask, nudge::image_t::FORMAT_PNG, msg.utime, 12, "right");
    run.bus.publish(channel::LEARN_VIEW, &msg);
    return run.commit("run_6", key, 13, t0 + 14 * kSecond, seq);
  };
  const auto boxed = learn("boxed", {}, 100 * kSecond, 1);
  const auto masked = learn("masked", mask, 200 * kSecond, 2);
  ASSERT_TRUE(boxed.ok && masked.ok) << boxed.reason << masked.reason;
  EXPECT_EQ(boxed.views_used, 13);
  EXPECT_EQ(masked.views_used, 13);
  EXPECT_LT(masked.descriptors, boxed.descriptors);  // the outline and what stands beside it
  EXPECT_EQ(masked.descriptors + masked.descriptors_pruned, boxed.descriptors + boxed.descriptors_pruned);
  EXPECT_TRUE(fs::exists(db + "/masked/view_12_mask.png"));
  EXPECT_FALSE(fs::exists(db + "/boxed/view_12_mask.png"));
  const int errors = run.service.counters().errors;
  const auto small = learn("small", cv::Mat(30, 40, CV_8UC1, cv::Scalar(255)), 300 * kSecond, 3);
  EXPECT_TRUE(small.ok) << "the turned views still serve";
  EXPECT_EQ(small.views_used, 12);
  EXPECT_EQ(run.service.counters().errors, errors + 1) << "the mask of another size is reported";
  fs::remove_all(db);
}

TEST(LearnerHandlers, BadInputIsReportedAndTheServiceKeepsAnswering) {
  const std::string db = fresh_db("bad");
  InProcess run(db);
  // An undecodable training image and a view index out of range: refused, named at the commit.
  auto views = turntable(12);
  auto broken = view_message("run_2", "attempt_01", 0, views[0], 10 * kSecond);
  broken.image.pixel_format = nudge::image_t::FORMAT_PNG;
  broken.image.data.assign(100, 0x42);
  broken.image.size = 100;
  broken.image.row_stride = 0;
  run.bus.publish(channel::LEARN_VIEW, &broken);
  auto outside = view_message("run_2", "attempt_01", 500, views[1], 11 * kSecond);
  run.bus.publish(channel::LEARN_VIEW, &outside);
  auto commit = commit_message("run_2", "attempt_01", "", 2, 12 * kSecond, 1);
  run.bus.publish(channel::LEARN_COMMIT, &commit);
  run.service.handle_pending();
  ASSERT_TRUE(run.learned.has());
  nudge::learn_result_t result = run.learned.get();
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.object_name, "run_2_attempt_01");
  EXPECT_NE(result.reason.find("no usable views received for run 'run_2' object 'attempt_01'"), std::string::npos)
      << result.reason;
  EXPECT_NE(result.reason.find("view 0: undecodable image"), std::string::npos) << result.reason;
  EXPECT_NE(result.reason.find("view 500: view_index outside"), std::string::npos) << result.reason;
  EXPECT_EQ(run.service.counters().errors, 3);

  // A commit for a key never sent.
  commit = commit_message("run_9", "nobody", "", 12, 13 * kSecond, 2);
  run.bus.publish(channel::LEARN_COMMIT, &commit);
  run.service.handle_pending();
  result = run.learned.get();
  EXPECT_EQ(result.seq, 2);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.reason.find("run 'run_9' object 'nobody'"), std::string::npos) << result.reason;

  // Views never committed expire after --view-expiry of message time; their commit then fails.
  auto early = view_message("run_3", "attempt_01", 0, views[0], 20 * kSecond);
  run.bus.publish(channel::LEARN_VIEW, &early);
  run.service.handle_pending();
  EXPECT_EQ(run.handlers->pending_objects(), 1);
  auto later = view_message("run_3", "attempt_02", 0, views[0], 200 * kSecond);
  run.bus.publish(channel::LEARN_VIEW, &later);
  run.service.handle_pending();
  EXPECT_EQ(run.handlers->pending_objects(), 1) << "attempt_01 expired, attempt_02 waits";
  commit = commit_message("run_3", "attempt_01", "", 1, 201 * kSecond, 3);
  run.bus.publish(channel::LEARN_COMMIT, &commit);
  run.service.handle_pending();
  EXPECT_FALSE(run.learned.get().ok);
  EXPECT_EQ(run.learned.get().seq, 3);

  // An undecodable image to recognise, then a good one: both answered.
  auto bad_request = request(syn::random_texture({64, 48}, 1), 20, false);
  bad_request.image.data.assign(bad_request.image.data.size(), 0);
  run.bus.publish(channel::RECOGNIZE_REQUEST, &bad_request);
  run.service.handle_pending();
  ASSERT_TRUE(run.recognition.has());
  EXPECT_EQ(run.recognition.get().seq, 20);
  EXPECT_EQ(run.recognition.get().label, "");
  EXPECT_NE(run.recognition.get().reason.find("undecodable image"), std::string::npos);
  const auto good = request(syn::random_texture({320, 240}, 2), 21, true);
  run.bus.publish(channel::RECOGNIZE_REQUEST, &good);
  run.service.handle_pending();
  EXPECT_EQ(run.recognition.get().seq, 21);
  EXPECT_EQ(run.recognition.get().reason, "empty database");
  EXPECT_EQ(run.recognition.get().match_picture.size, 0);
  EXPECT_TRUE(fs::is_empty(db)) << "nothing stored from bad input";
  fs::remove_all(db);
}

TEST(LearnerHandlers, AnObjectLearnedWithOtherSiftSettingsIsLoadedAndReportedByName) {
  const std::string db = fresh_db("sift_settings");
  namespace learning = nudge::learning;
  auto stored = [&db](const std::string& name, double contrast) {
    learning::LearnParams params;
    params.sift.contrast_threshold = contrast;
    learning::ObjectInfo info;
    info.name = name;
    learning::ObjectDatabase(db).store(
        learning::learn_object(info, syn::turntable_views(syn::random_texture({400, 200}, 31), syn::random_texture({400, 300}, 32),
                                                          {150, 50, 100, 200}, 4),
                               params));
  };
  stored("as_this_learner", learning::SiftParams{}.contrast_threshold);
  stored("at_opencvs_default", 0.04);
  InProcess run(db);
  EXPECT_EQ(run.handlers->known_objects(), 2);  // both still known
  EXPECT_EQ(run.service.counters().errors, 1);  // one said, at load
  fs::remove_all(db);
}

// The worker alone, its job held at a gate: a queue of one, progress in the status, errors kept.
TEST(LearnWorker, OneJobAtATimeWithProgressAndErrors) {
  nudge::learner_service::LearnWorker worker;
  EXPECT_FALSE(worker.busy());
  EXPECT_EQ(worker.status(), "");
  std::promise<void> reached, release;
  std::shared_future<void> released = release.get_future().share();
  ASSERT_TRUE(worker.submit("attempt_03", [&](const nudge::learner_service::LearnWorker::Progress& progress) {
    progress(3, 12);
    reached.set_value();
    released.wait();
  }));
  reached.get_future().wait();
  EXPECT_TRUE(worker.busy());
  EXPECT_EQ(worker.status(), "learning attempt_03 (view 3/12)");
  EXPECT_FALSE(worker.submit("attempt_04", [](const auto&) {})) << "a second job while one runs";
  EXPECT_FALSE(worker.take_ended().has_value()) << "nothing ended yet";
  release.set_value();
  worker.wait_until_ended();
  EXPECT_EQ(worker.status(), "");
  EXPECT_TRUE(worker.busy()) << "busy until its end is taken";
  EXPECT_FALSE(worker.submit("attempt_04", [](const auto&) {})) << "the end not taken yet";
  auto ended = worker.take_ended();
  ASSERT_TRUE(ended.has_value());
  EXPECT_EQ(ended->what, "attempt_03");
  EXPECT_EQ(ended->error, "");
  EXPECT_FALSE(worker.busy());

  ASSERT_TRUE(worker.submit("attempt_04", [](const auto&) { throw std::runtime_error("disk full"); }));
  worker.wait_until_ended();
  ended = worker.take_ended();
  ASSERT_TRUE(ended.has_value());
  EXPECT_EQ(ended->what, "attempt_04");
  EXPECT_EQ(ended->error, "disk full");
}

// While it learns, the learner answers: its heartbeat says what it learns, a recognition request
// is answered, a second commit is refused with the reason and its views kept for the resend.
TEST(LearnerHandlers, StaysResponsiveWhileLearning) {
  const std::string db = fresh_db("busy");
  InProcess run(db);
  nudge::bus::Subscriptions beats(run.bus, run.probe_counters);
  Latest<nudge::heartbeat_t> beat(beats, channel::HEARTBEAT);
  run.teach("run_4", "attempt_01", 21, 100 * kSecond);
  run.teach("run_4", "attempt_02", 22, 130 * kSecond);
  auto first = commit_message("run_4", "attempt_01", "first", 12, 120 * kSecond, 1);
  run.bus.publish(channel::LEARN_COMMIT, &first);
  run.service.handle_pending();  // returns with the job on the worker (busy until poll() takes its end)
  EXPECT_TRUE(run.handlers->learning());
  EXPECT_FALSE(run.learned.has()) << "LEARNED only when the worker is done";
  run.service.publish_heartbeat_at(150 * kSecond);
  run.service.handle_pending();
  ASSERT_TRUE(beat.has());
  EXPECT_EQ(beat.get().status.rfind("learning attempt_01", 0), 0u) << beat.get().status;

  const auto ask = request(syn::random_texture({320, 240}, 3), 30, false);
  run.bus.publish(channel::RECOGNIZE_REQUEST, &ask);
  auto second = commit_message("run_4", "attempt_02", "second", 12, 145 * kSecond, 2);
  run.bus.publish(channel::LEARN_COMMIT, &second);
  run.service.handle_pending();
  ASSERT_TRUE(run.recognition.has());
  EXPECT_EQ(run.recognition.get().seq, 30);
  ASSERT_TRUE(run.learned.has());
  EXPECT_EQ(run.learned.get().seq, 2);
  EXPECT_FALSE(run.learned.get().ok);
  EXPECT_EQ(run.learned.get().reason.rfind("busy learning attempt_01", 0), 0u) << run.learned.get().reason;
  EXPECT_EQ(run.handlers->pending_objects(), 1) << "the refused commit's views are kept";

  run.handlers->finish_learning();
  run.service.handle_pending();
  EXPECT_EQ(run.learned.get().seq, 1);
  EXPECT_TRUE(run.learned.get().ok) << run.learned.get().reason;
  EXPECT_FALSE(run.handlers->learning());
  run.service.publish_heartbeat_at(160 * kSecond);
  run.service.handle_pending();
  EXPECT_EQ(beat.get().status.find("learning"), std::string::npos) << beat.get().status;

  run.bus.publish(channel::LEARN_COMMIT, &second);  // sent again: learned now
  run.service.handle_pending();
  run.handlers->finish_learning();
  run.service.handle_pending();
  EXPECT_EQ(run.learned.get().seq, 2);
  EXPECT_TRUE(run.learned.get().ok) << run.learned.get().reason;
  EXPECT_EQ(run.handlers->known_objects(), 2);
  fs::remove_all(db);
}
