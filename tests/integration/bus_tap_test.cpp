// Integration: over UDP multicast (a private network namespace), LCM 1.3.1 keeps a queue per
// subscription and drops per subscription when one is full. A recorder that logs through a
// catch-all subscription of its own therefore logs frames a stream handler skipped (and, with a
// bounded queue, misses messages it handled), and a replay of that log decides on other inputs:
// SupervisorLearn's replay once stopped at RECOGNISE because the run's log lacked the RECOGNITION
// the run had handled. The Subscriptions' tap logs exactly what the typed handlers were given.
// Needs root for the namespace: skipped otherwise.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <string>
#include <vector>

#include "nudge/bus/subscribe.hpp"
#include "nudge/image_t.hpp"
#include "nudge/test/private_network.hpp"

namespace {

struct CatchAll {
  int count = 0;
  void on_message(const lcm::ReceiveBuffer*, const std::string&) { ++count; }
};

}  // namespace

TEST(BusTap, LogsWhatAStreamHandlerWasGivenNotWhatItSkipped) {
  NUDGE_TEST_ENTER_PRIVATE_NETWORK();
  lcm::LCM lcm(nudge::test::kPrivateLcmUrl);
  ASSERT_TRUE(lcm.good());
  nudge::bus::Counters counters;
  nudge::bus::Subscriptions subscriptions(lcm, counters);
  std::vector<int64_t> handled, tapped;
  subscriptions.subscribe<nudge::image_t>("CAMERA_TAP", [&](const nudge::image_t& m, const std::string&) { handled.push_back(m.frame_id); });
  subscriptions.set_stream_queue_capacity(2);  // a handler that fell behind keeps the newest few
  subscriptions.set_tap([&](const lcm::ReceiveBuffer* rbuf, const std::string&) {
    nudge::image_t m;
    if (m.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) >= 0) tapped.push_back(m.frame_id);
  });
  CatchAll catch_all;
  lcm.subscribe(".*", &CatchAll::on_message, &catch_all)->setQueueCapacity(0);  // no limit

  // 20 frames sent while nobody handles: LCM's receive thread queues what each subscription has
  // room for.
  constexpr int kFrames = 20;
  for (int i = 0; i < kFrames; ++i) {
    nudge::image_t m{};
    m.frame_id = i;
    m.width = m.height = 1;
    m.row_stride = 1;
    m.pixel_format = nudge::image_t::FORMAT_GRAY8;
    m.size = 1;
    m.data = {0};
    lcm.publish("CAMERA_TAP", &m);
  }
  for (int idle = 0; idle < 5;) idle = lcm.handleTimeout(200) > 0 ? 0 : idle + 1;

  EXPECT_EQ(catch_all.count, kFrames) << "the catch-all, unbounded, got every frame";
  EXPECT_LT(handled.size(), static_cast<size_t>(kFrames)) << "the stream handler skipped some";
  EXPECT_EQ(tapped, handled) << "the tap: exactly the frames handled, in order";
}
