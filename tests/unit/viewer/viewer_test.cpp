// nudge_viewer: service health from heartbeats, the supervisor's timeline, the pacing of a
// replayed log, and the page's JSON (the view model), without LCM or HTTP.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <thread>

#include "nudge/viewer/health.hpp"
#include "nudge/viewer/replay_pacer.hpp"
#include "nudge/viewer/timeline.hpp"
#include "nudge/viewer/view_model.hpp"

using namespace nudge::viewer;

namespace {

constexpr int64_t kSecond = 1'000'000;

Heartbeat beat(const std::string& service, int64_t seen, int64_t in, int pid = 7) {
  Heartbeat hb;
  hb.service = service;
  hb.pid = pid;
  hb.state = "running";
  hb.messages_in = in;
  hb.messages_out = in / 2;
  hb.seen_utime = seen;
  return hb;
}

}  // namespace

TEST(HealthTable, RatesComeFromTheLastTwoHeartbeats) {
  HealthTable table;
  table.observe(beat("symmetry", 10 * kSecond, 100));
  auto rows = table.rows({10 * kSecond, 0});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].heartbeat_hz, 0) << "one heartbeat gives no rate";
  table.observe(beat("symmetry", 11 * kSecond, 130));
  rows = table.rows({11 * kSecond + kSecond / 2, 0});
  EXPECT_DOUBLE_EQ(rows[0].in_per_s, 30);
  EXPECT_DOUBLE_EQ(rows[0].out_per_s, 15);
  EXPECT_DOUBLE_EQ(rows[0].heartbeat_hz, 1);
  EXPECT_DOUBLE_EQ(rows[0].last_seen_s, 0.5);
  EXPECT_TRUE(rows[0].alive);
}

TEST(HealthTable, AServiceSilentLongerThanTheLimitIsDead) {
  HealthTable table(2.5);
  table.observe(beat("camera", 0, 0));
  table.observe(beat("tracker", 0, 0));
  table.observe(beat("camera", 2 * kSecond, 10));
  const auto rows = table.rows({2600000, 0});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].name, "camera");
  EXPECT_TRUE(rows[0].alive);
  EXPECT_EQ(rows[1].name, "tracker");
  EXPECT_FALSE(rows[1].alive) << "silent 2.6 s > 2.5 s: red within 3 s of its last heartbeat";
}

TEST(HealthTable, ARestartedProcessStartsItsRatesAfreshAndInstancesAreRowsOfTheirOwn) {
  HealthTable table;
  table.observe(beat("arm", 0, 500, 7));
  table.observe(beat("arm", kSecond, 3, 8));  // new pid: counters restarted
  Heartbeat other = beat("arm", kSecond, 0);
  other.instance = "b";
  table.observe(other);
  const auto rows = table.rows({kSecond, 0});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].name, "arm");
  EXPECT_EQ(rows[0].pid, 8);
  EXPECT_EQ(rows[0].in_per_s, 0) << "no negative rate across a restart";
  EXPECT_EQ(rows[1].name, "arm/b");
}

TEST(HealthTable, LogHeartbeatsAreJudgedAtTheReplaysPosition) {
  HealthTable table;
  Heartbeat logged = beat("symmetry", 100 * kSecond, 0);
  logged.log_time = true;
  table.observe(logged);
  table.observe(beat("viewer", 5000 * kSecond, 0));
  const auto rows = table.rows({5001 * kSecond, 101 * kSecond});
  EXPECT_DOUBLE_EQ(rows[0].last_seen_s, 1) << rows[0].name;
  EXPECT_DOUBLE_EQ(rows[1].last_seen_s, 1) << rows[1].name;
}

TEST(StateTimeline, RepeatsRefreshCountsAndTransitionsAppend) {
  StateTimeline timeline(3);
  StateEntry e;
  e.state = "NUDGE";
  e.attempt = 1;
  e.reason = "nudging";
  EXPECT_TRUE(timeline.observe(e));
  e.segmented = 2;
  EXPECT_FALSE(timeline.observe(e)) << "the supervisor's 1 Hz repeat";
  EXPECT_EQ(timeline.entries().back().segmented, 2);
  e.state = "SEGMENT";
  EXPECT_TRUE(timeline.observe(e));
  e.state = "NUDGE";
  e.attempt = 2;
  EXPECT_TRUE(timeline.observe(e));
  e.state = "DONE";
  EXPECT_TRUE(timeline.observe(e));
  ASSERT_EQ(timeline.entries().size(), 3u) << "capped, oldest dropped";
  EXPECT_EQ(timeline.entries().front().state, "SEGMENT");
}

TEST(ReplayPacer, KeepsTheLogsSpacingAtItsSpeed) {
  ReplayPacer pacer(2.0);
  const int64_t wall = 1000 * kSecond, log = 50 * kSecond;
  EXPECT_EQ(pacer.wait_us(log, wall), 0) << "the first event plays at once";
  pacer.released(log, false, wall);
  EXPECT_EQ(pacer.wait_us(log + kSecond, wall), kSecond / 2) << "1 s of log at x2";
  EXPECT_EQ(pacer.wait_us(log + kSecond, wall + kSecond), 0) << "late events are due at once";
  pacer.released(log + kSecond, false, wall + kSecond);
  EXPECT_EQ(pacer.position(), log + kSecond);
  pacer.set_speed(1.0, wall + kSecond);
  EXPECT_EQ(pacer.wait_us(log + 2 * kSecond, wall + kSecond), kSecond) << "re-anchored at the new speed";
}

TEST(ReplayPacer, ALogWhoseTimeGoesBackKeepsItsSpacingFromThere) {
  ReplayPacer pacer(1.0);
  const int64_t wall = 1000 * kSecond, log = 50 * kSecond;
  pacer.released(log, false, wall);
  pacer.released(log + 10 * kSecond, false, wall + 10 * kSecond);
  // The second of two logs back to back starts 10 s earlier: due at once, then re-anchored.
  EXPECT_EQ(pacer.wait_us(log, wall + 10 * kSecond), 0);
  pacer.released(log, false, wall + 10 * kSecond);
  EXPECT_EQ(pacer.wait_us(log + kSecond, wall + 10 * kSecond), kSecond) << "its own spacing, not a burst";
}

TEST(ReplayPacer, PausesStepsToTheNextStepEventAndResumesWhereItStopped) {
  ReplayPacer pacer(1.0, /*paused=*/true);
  const int64_t wall = 1000 * kSecond, log = 50 * kSecond;
  EXPECT_EQ(pacer.wait_us(log, wall), -1) << "paused: wait for a command";
  pacer.step();
  EXPECT_EQ(pacer.wait_us(log, wall), 0);
  pacer.released(log, /*is_step_event=*/false, wall);
  EXPECT_TRUE(pacer.stepping()) << "a heartbeat is not a frame";
  EXPECT_EQ(pacer.wait_us(log + kSecond, wall), 0) << "a step does not wait for the log's spacing";
  pacer.released(log + kSecond, /*is_step_event=*/true, wall);
  EXPECT_FALSE(pacer.stepping());
  EXPECT_TRUE(pacer.paused());
  EXPECT_EQ(pacer.wait_us(log + 2 * kSecond, wall + 60 * kSecond), -1);
  pacer.play(wall + 60 * kSecond);  // a minute later: the next event is 1 s of log away, not overdue
  EXPECT_EQ(pacer.wait_us(log + 2 * kSecond, wall + 60 * kSecond), kSecond);
  EXPECT_THROW(pacer.set_speed(0, wall), std::invalid_argument);
  EXPECT_THROW(ReplayPacer(-1), std::invalid_argument);
}

TEST(ReplayCommand, NamesRoundTripAndUnknownOnesAreNamedInTheError) {
  for (const auto c : {ReplayCommand::kPlay, ReplayCommand::kPause, ReplayCommand::kStep, ReplayCommand::kSpeed})
    EXPECT_EQ(replay_command_from_name(replay_command_name(c)), c);
  try {
    replay_command_from_name("rewind");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rewind"), std::string::npos);
  }
}

TEST(ViewModel, ServesEachFrameAsJpegOnceItCameAndMeasuresTheCamerasRate) {
  ViewModel model;
  JpegFrame frame;
  EXPECT_FALSE(model.wait_frame("left", -1, 0, &frame)) << "no camera yet";
  cv::Mat image(48, 64, CV_8UC3, cv::Scalar(0, 0, 255));
  for (int i = 0; i < 5; ++i) model.set_frame("left", image, i * kSecond / 20);  // 20 Hz
  ASSERT_TRUE(model.wait_frame("left", 0, 0, &frame));
  EXPECT_EQ(frame.seq, 5);
  EXPECT_EQ(frame.width, 64);
  const cv::Mat decoded = cv::imdecode(frame.jpeg, cv::IMREAD_COLOR);
  ASSERT_FALSE(decoded.empty());
  EXPECT_GT(decoded.at<cv::Vec3b>(20, 20)[2], 200) << "red stays red";
  EXPECT_NEAR(model.to_json(0)["cameras"]["left"]["fps"].get<double>(), 20.0, 1e-9) << "from the frames' stamps";
  EXPECT_FALSE(model.wait_frame("left", 5, 10, &frame)) << "nothing newer than frame 5";
  std::thread later([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    model.set_frame_jpeg("left", {0xff, 0xd8, 0xff}, 64, 48, kSecond);
  });
  EXPECT_TRUE(model.wait_frame("left", 5, 5000, &frame)) << "the waiting request gets the next frame";
  later.join();
  EXPECT_EQ(frame.jpeg.size(), 3u) << "a JPEG frame is served as it came";
}

TEST(ViewModel, JsonCarriesOverlaysTableTimelineMasksAndHealth) {
  ViewModel model;
  ImageLine line;
  line.x1 = 10;
  model.set_lines("right", {line, line}, 5);
  TrackOverlay track;
  track.status = "tracking";
  track.box[2][1] = 7;
  model.set_track("right", track);
  Candidate c;
  c.position[0] = 0.3;
  c.cluster_size = 4;
  model.set_candidates({c}, 9);
  PlannedPush push;
  push.target[1] = 0.1;
  model.set_push(push);
  StateEntry s;
  s.state = "NUDGE";
  s.has_target = true;
  model.observe_state(s);
  Segmentation seg;
  seg.attempt = 1;
  seg.png = {1, 2, 3};
  model.add_segmentation(seg);
  model.observe_heartbeat(beat("camera", 0, 0), 123, 10 * kSecond);
  ProcessRow process;
  process.name = "symmetry";
  process.state = "restarting";
  process.restarts = 2;
  model.set_processes({process});
  const auto j = model.to_json(11 * kSecond);
  EXPECT_EQ(j["mode"], "live");
  EXPECT_EQ(j["cameras"]["right"]["lines"].size(), 2u);
  EXPECT_EQ(j["cameras"]["right"]["lines"][0]["x1"], 10);
  EXPECT_EQ(j["cameras"]["right"]["track"]["box"][2][1], 7);
  EXPECT_EQ(j["table"]["candidates"][0]["cluster_size"], 4);
  EXPECT_EQ(j["table"]["candidates_frame"], "table") << "as the triangulation sends them";
  EXPECT_EQ(j["table"]["push"]["target"][1], 0.1);
  EXPECT_EQ(j["supervisor"]["current"]["state"], "NUDGE");
  EXPECT_EQ(j["segmentations"][0]["url"], "/api/mask/0");
  std::vector<uint8_t> png;
  EXPECT_TRUE(model.mask_png(0, &png));
  EXPECT_EQ(png.size(), 3u);
  EXPECT_FALSE(model.mask_png(1, &png));
  EXPECT_DOUBLE_EQ(j["health"][0]["last_seen_s"].get<double>(), 1.0) << "live: judged by the arrival time";
  EXPECT_TRUE(j["replay"].is_null());
  EXPECT_EQ(j["processes"][0]["state"], "restarting");
  EXPECT_EQ(j["processes"][0]["restarts"], 2);
}

TEST(ViewModel, SaysWhichFrameTheCandidatesAreIn) {
  ViewModel model;
  Candidate c;
  c.position[1] = -0.02;
  model.set_candidates({c}, 9, true);
  auto j = model.to_json(kSecond);
  EXPECT_EQ(j["table"]["candidates_frame"], "world");
  EXPECT_EQ(j["table"]["candidates"][0]["position"][1], -0.02);
  model.set_candidates({c}, 10);
  j = model.to_json(kSecond);
  EXPECT_EQ(j["table"]["candidates_frame"], "table");
}

TEST(ViewModel, OnAReplayTheLogsHeartbeatsGoByLogTimeAndLiveOnesByArrival) {
  ViewModel model;
  ReplayStatus replay;
  replay.state = "playing";
  replay.start_utime = 100 * kSecond;
  replay.end_utime = 200 * kSecond;
  replay.position_utime = 150 * kSecond;
  replay.received_wall_utime = 9000 * kSecond;
  model.set_replay(replay);
  model.observe_heartbeat(beat("tracker", 0, 0), 140 * kSecond, 8999 * kSecond);  // from the log
  model.observe_heartbeat(beat("viewer", 0, 0), 9000 * kSecond, 9000 * kSecond);  // live
  model.observe_heartbeat(beat("viewer", 0, 0), 149 * kSecond, 9000 * kSecond);   // the recorded run's viewer
  const auto j = model.to_json(9000 * kSecond);
  EXPECT_EQ(j["mode"], "replay");
  ASSERT_EQ(j["health"].size(), 3u) << j["health"].dump();
  EXPECT_EQ(j["health"][0]["name"], "tracker");
  EXPECT_FALSE(j["health"][0]["alive"]) << "10 s of log without a heartbeat";
  EXPECT_EQ(j["health"][1]["name"], "viewer") << "the log's";
  EXPECT_TRUE(j["health"][1]["alive"]);
  EXPECT_EQ(j["health"][2]["name"], "viewer/(live)") << "the live one: its own row, not mixed with the log's";
  EXPECT_TRUE(j["health"][2]["alive"]);
  EXPECT_TRUE(j["replay"]["connected"]);
}
