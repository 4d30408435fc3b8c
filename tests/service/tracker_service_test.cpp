// Service test: the tracker service as a function from log to log, through LCM's file provider.
// The input log holds synthetic 640x480 frames of a bottle that rests, then moves and rotates in
// front of a static scene, a truncated image and a restart request; the output must track it.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/track_t.hpp"
#include "nudge/tracker_command_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/run_service.hpp"

namespace syn = nudge::symmetry::synthetic;
namespace channel = nudge::bus::channel;

namespace {

using nudge::test::encode;
using nudge::test::LogWriter;
using nudge::test::run_from_log;

constexpr double kDeg = M_PI / 180.0;
constexpr int64_t kStart = 1000000, kPeriod = 40000;  // 25 fps
constexpr int kFrames = 40, kStillFrames = 4, kRestartAfter = 25;
// Copies of track_t's status constants (gtest's macros take references, which those do not have).
constexpr int kIdle = nudge::track_t::STATUS_IDLE, kTracking = nudge::track_t::STATUS_TRACKING,
              kLost = nudge::track_t::STATUS_LOST;

struct Truth {
  double r, theta;
};

Truth truth(int frame) {
  const double t = std::max(0, frame - kStillFrames);
  return {-120.0 + 3.5 * t + 0.02 * t * t, (-8.0 + 0.4 * t) * kDeg};
}

// Static clutter (including a symmetric cup that must not be tracked) and a shaded moving bottle.
cv::Mat frame(int i) {
  cv::Mat img(480, 640, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) img.at<uint8_t>(y, x) = static_cast<uint8_t>(170 + 30.0 * x / img.cols);
  cv::rectangle(img, cv::Rect(0, 360, 640, 120), cv::Scalar(140), cv::FILLED);
  syn::draw_shape(img, syn::cup_profile(144, 38, 29), 192, 0.0, 0, cv::Scalar(60));
  const Truth t = truth(i);
  const double shades[] = {1.0, 0.8, 0.6, 0.4};
  for (int k = 0; k < 4; ++k)
    syn::draw_shape(img, syn::bottle_profile(220, 40 * shades[k]), t.r, t.theta, 0, cv::Scalar(40 + 25 * k));
  return img;
}

void write_input_log(const std::string& path) {
  LogWriter log(path);
  for (int i = 0; i < kFrames; ++i) {
    const int64_t utime = kStart + kPeriod * i;
    const auto image = nudge::bus::to_message(frame(i), nudge::image_t::FORMAT_GRAY8, utime, i, "left");
    log.write(utime, channel::CAMERA_LEFT, image);
    if (i == 10) {  // a truncated image: reported, counted and skipped
      auto bytes = encode(image);
      bytes.resize(bytes.size() / 3);
      log.raw(utime + 1, channel::CAMERA_LEFT, bytes);
    }
    if (i == kRestartAfter) {
      nudge::tracker_command_t cmd{};
      cmd.utime = utime + 2;
      cmd.channel = channel::TRACK_LEFT;
      cmd.command = nudge::tracker_command_t::COMMAND_RESTART;
      cmd.reason = "operator restart";
      log.write(utime + 2, channel::TRACKER_COMMAND, cmd);
    }
  }
}

int run(const std::string& args) { return nudge::test::run_command(nudge::test::bin_dir() + "/nudge-tracker" + args); }

}  // namespace

TEST(TrackerService, LogInLogOutTracksTheMovingBottleAndRestartsOnRequest) {
  const std::string in = nudge::test::temp_path("tracker_in.lcmlog");
  write_input_log(in);
  const auto run = run_from_log("nudge-tracker", "", in, nudge::test::temp_path("tracker_out.lcmlog"));
  ASSERT_EQ(run.exit_code, 0) << run.command;

  std::map<int64_t, nudge::track_t> tracks;
  for (const auto& msg : nudge::test::messages_on<nudge::track_t>(run.output, channel::TRACK_LEFT)) tracks[msg.frame_id] = msg;
  EXPECT_TRUE(nudge::test::messages_on<nudge::track_t>(run.output, channel::TRACK_RIGHT).empty())
      << "no right frames, no right tracks";
  const auto heartbeats = nudge::test::messages_on<nudge::heartbeat_t>(run.output, channel::HEARTBEAT);
  ASSERT_FALSE(heartbeats.empty());
  const nudge::heartbeat_t& last_heartbeat = heartbeats.back();
  ASSERT_EQ(tracks.size(), static_cast<size_t>(kFrames)) << "one TRACK_LEFT per good frame";
  EXPECT_EQ(last_heartbeat.errors, 1) << "the truncated image";
  EXPECT_NE(last_heartbeat.status.find("TRACK_RIGHT idle, no frames on CAMERA_RIGHT yet"), std::string::npos)
      << last_heartbeat.status;

  EXPECT_EQ(tracks.at(0).status, kIdle);
  int first_tracking = -1, tracked = 0;
  double sum_r = 0, sum_theta = 0;
  for (int i = 0; i <= kRestartAfter; ++i) {
    const nudge::track_t& m = tracks.at(i);
    EXPECT_EQ(m.camera, "left");
    EXPECT_EQ(m.utime, kStart + kPeriod * i);
    if (m.status != kTracking) continue;
    if (first_tracking < 0) first_tracking = i;
    ++tracked;
    sum_r += std::fabs(m.line.r - truth(i).r);
    sum_theta += std::fabs(m.line.theta - truth(i).theta) / kDeg;
    EXPECT_EQ(m.block_size, 8);
    EXPECT_EQ(m.blocks_w, 80);
    EXPECT_EQ(m.blocks_h, 60);
    ASSERT_EQ(m.num_blocks, 80 * 60);
    EXPECT_GT(m.covariance[0][0], 0.f);
    EXPECT_GT(m.covariance[1][1], 0.f);
    EXPECT_NE(m.box[0][0], m.box[2][0]);
  }
  ASSERT_GE(first_tracking, 0) << tracks.at(kRestartAfter).reason;
  EXPECT_LE(first_tracking, kStillFrames + 3);
  EXPECT_EQ(tracked, kRestartAfter + 1 - first_tracking);
  EXPECT_LT(sum_r / tracked, 2.0);
  EXPECT_LT(sum_theta / tracked, 2.0);

  // The restart: reported on the next frame, then the automatic start finds the bottle again.
  const nudge::track_t& after = tracks.at(kRestartAfter + 1);
  EXPECT_EQ(after.status, kLost);
  EXPECT_EQ(after.reason, "operator restart");
  int again = -1;
  for (int i = kRestartAfter + 1; i < kFrames && again < 0; ++i)
    if (tracks.at(i).status == kTracking) again = i;
  ASSERT_GE(again, 0);
  EXPECT_LE(again, kRestartAfter + 5);
  const nudge::track_t& last = tracks.at(kFrames - 1);
  EXPECT_EQ(last.status, kTracking);
  EXPECT_NEAR(last.line.r, truth(kFrames - 1).r, 2.0);
  EXPECT_NEAR(last.line.theta, truth(kFrames - 1).theta, 2.0 * kDeg);
}

TEST(TrackerService, AStoppedStreamIsReportedInTheHeartbeat) {
  // Played at recorded speed: five frames, then 2.5 s of silence before the log's last event.
  const std::string in = nudge::test::temp_path("tracker_stale_in.lcmlog"),
                    out = nudge::test::temp_path("tracker_stale_out.lcmlog");
  std::remove(out.c_str());
  {
    LogWriter log(in);
    for (int i = 0; i < 5; ++i) {
      cv::Mat small;
      cv::resize(frame(i), small, cv::Size(160, 120));
      log.write(kStart + kPeriod * i, channel::CAMERA_LEFT,
                nudge::bus::to_message(small, nudge::image_t::FORMAT_GRAY8, kStart + kPeriod * i, i, "left"));
    }
    nudge::tracker_command_t cmd{};
    cmd.command = nudge::tracker_command_t::COMMAND_RESTART;
    log.write(kStart + kPeriod * 5 + 2500000, channel::TRACKER_COMMAND, cmd);
  }
  ASSERT_EQ(run(" --inputs CAMERA_LEFT --stale 0.5 --lcm-in 'file://" + in + "?speed=1' --lcm-out 'file://" + out +
                "?mode=w'"),
            0);
  bool reported = false;
  for (const auto& hb : nudge::test::read_messages<nudge::heartbeat_t>(out, channel::HEARTBEAT))
    reported = reported || hb.status.find("CAMERA_LEFT stopped") != std::string::npos;
  EXPECT_TRUE(reported) << "a heartbeat during the silence names the stopped stream";
}

TEST(TrackerService, BadFlagsAreRefusedWithAUsageError) {
  for (const std::string args : {" --dmin 300 --dmax 100", " --theta-min -200", " --max-missed 0",
                                 " --inputs A,B --outputs C", " --stale 0", " --no-such-flag"}) {
    EXPECT_EQ(run(args + " 2>/dev/null"), 2) << args;
  }
}
