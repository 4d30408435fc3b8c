// track_t <-> nudge::tracking (nudge_bus_tracking).
#include <gtest/gtest.h>

#include "nudge/bus/track_convert.hpp"

using namespace nudge;

namespace {

tracking::TrackState tracking_state() {
  tracking::TrackState s;
  s.status = tracking::TrackStatus::Tracking;
  s.reason = "";
  s.utime = 99;
  s.has_estimate = true;
  s.line.r = -12.5;
  s.line.theta = 0.125;
  s.line.end1 = {10, 0};
  s.line.end2 = {14, 239};
  s.covariance << 2.0, 0.25, 0.25, 0.5;
  s.has_box = true;
  s.box = {cv::Point2d(1, 2), cv::Point2d(3, 4), cv::Point2d(5, 6), cv::Point2d(7, 8)};
  s.block_size = 8;
  s.tracks_started = 3;
  s.blocks = cv::Mat::zeros(3, 4, CV_8U);
  s.blocks.at<uint8_t>(1, 2) = 1;
  s.blocks.at<uint8_t>(2, 3) = 1;
  return s;
}

}  // namespace

TEST(TrackConvert, TrackingStateRoundTrips) {
  const tracking::TrackState s = tracking_state();
  const track_t msg = bus::to_message(s, 1234, 7, "left");
  EXPECT_EQ(msg.utime, 1234);
  EXPECT_EQ(msg.frame_id, 7);
  EXPECT_EQ(msg.camera, "left");
  EXPECT_EQ(msg.status + 0, track_t::STATUS_TRACKING + 0);  // + 0: the constant has no definition to bind to
  EXPECT_EQ(msg.num_blocks, 12);

  const tracking::TrackState back = bus::from_message(msg);
  EXPECT_EQ(back.status, tracking::TrackStatus::Tracking);
  EXPECT_EQ(back.utime, 1234);
  EXPECT_TRUE(back.has_estimate);
  EXPECT_FLOAT_EQ(back.line.r, -12.5);
  EXPECT_FLOAT_EQ(back.line.theta, 0.125);
  EXPECT_FLOAT_EQ(back.line.end2.y, 239);
  EXPECT_FLOAT_EQ(back.covariance(0, 1), 0.25);
  EXPECT_FLOAT_EQ(back.covariance(1, 1), 0.5);
  ASSERT_TRUE(back.has_box);
  EXPECT_FLOAT_EQ(back.box[3].x, 7);
  EXPECT_EQ(back.block_size, 8);
  EXPECT_EQ(msg.tracks_started, 3);
  EXPECT_EQ(back.tracks_started, 3);
  ASSERT_EQ(back.blocks.size(), s.blocks.size());
  EXPECT_EQ(cv::norm(back.blocks, s.blocks, cv::NORM_INF), 0);
}

TEST(TrackConvert, IdleStateHasNoEstimateNorBox) {
  tracking::TrackState idle;
  idle.reason = "no motion yet";
  const tracking::TrackState back = bus::from_message(bus::to_message(idle, 5, 1, "right"));
  EXPECT_EQ(back.status, tracking::TrackStatus::Idle);
  EXPECT_EQ(back.reason, "no motion yet");
  EXPECT_FALSE(back.has_estimate);
  EXPECT_FALSE(back.has_box);
  EXPECT_TRUE(back.blocks.empty());
}

TEST(TrackConvert, InconsistentMessagesAreErrorsNamingTheField) {
  auto error_of = [](const track_t& m) {
    try {
      bus::from_message(m);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const track_t good = bus::to_message(tracking_state(), 1, 1, "left");
  track_t short_mask = good;
  short_mask.motion_mask.pop_back();
  EXPECT_NE(error_of(short_mask).find("num_blocks"), std::string::npos);
  track_t bad_shape = good;
  bad_shape.blocks_w = 5;
  EXPECT_NE(error_of(bad_shape).find("blocks_w"), std::string::npos);
  track_t bad_status = good;
  bad_status.status = 9;
  EXPECT_NE(error_of(bad_status).find("status"), std::string::npos);
}
