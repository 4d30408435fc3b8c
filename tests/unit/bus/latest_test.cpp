// nudge::bus::Latest: the newest message on a channel, its receive time and a count.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "nudge/bus/latest.hpp"
#include "nudge/heartbeat_t.hpp"

using nudge::heartbeat_t;
using nudge::bus::Counters;
using nudge::bus::Latest;
using nudge::bus::Subscriptions;

namespace {
heartbeat_t numbered(int64_t utime) {
  heartbeat_t hb{};
  hb.utime = utime;
  hb.service = "s" + std::to_string(utime);
  return hb;
}

// Handles everything queued on an in-process bus.
void pump(lcm::LCM& bus) {
  while (bus.handleTimeout(0) > 0) {
  }
}
}  // namespace

TEST(Latest, EmptyUntilTheFirstMessageAndTheErrorNamesTheChannel) {
  lcm::LCM bus("memq://");
  Counters counters;
  Subscriptions subscriptions(bus, counters);
  const Latest<heartbeat_t> latest(subscriptions, "STATE");
  EXPECT_FALSE(latest.has());
  EXPECT_EQ(latest.count(), 0);
  EXPECT_EQ(latest.channel(), "STATE");
  try {
    latest.get();
    FAIL() << "get() without a message";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("STATE"), std::string::npos) << e.what();
  }
  EXPECT_THROW(latest.age(0), std::logic_error);
}

TEST(Latest, KeepsTheNewestAndCountsThemAll) {
  lcm::LCM bus("memq://");
  Counters counters;
  Subscriptions subscriptions(bus, counters);
  const Latest<heartbeat_t> latest(subscriptions, "STATE");
  for (int64_t t : {3, 1, 2}) {
    const heartbeat_t msg = numbered(t);
    bus.publish("STATE", &msg);
  }
  const heartbeat_t other = numbered(99);
  bus.publish("OTHER", &other);
  pump(bus);
  ASSERT_TRUE(latest.has());
  EXPECT_EQ(latest.count(), 3);
  EXPECT_EQ(latest.get().utime, 2) << "the last to arrive, not the largest utime";
  EXPECT_EQ(latest.get().service, "s2");
  const int64_t received = latest.receive_utime();
  EXPECT_GT(received, 0);
  EXPECT_EQ(latest.age(received + 250000), 250000);
}

TEST(Latest, AMalformedMessageIsCountedByTheSubscriptionsAndKeepsTheHeldOne) {
  lcm::LCM bus("memq://");
  Counters counters;
  Subscriptions subscriptions(bus, counters);
  const Latest<heartbeat_t> latest(subscriptions, "STATE");
  const heartbeat_t good = numbered(5);
  bus.publish("STATE", &good);
  const std::vector<uint8_t> garbage = {9, 9};
  bus.publish("STATE", garbage.data(), static_cast<unsigned>(garbage.size()));
  pump(bus);
  EXPECT_EQ(latest.count(), 1);
  EXPECT_EQ(latest.get().utime, 5);
  EXPECT_EQ(counters.errors, 1);
  EXPECT_EQ(counters.messages_in, 2);
}

TEST(Latest, TheSubscriptionMayOutliveTheHolder) {
  lcm::LCM bus("memq://");
  Counters counters;
  Subscriptions subscriptions(bus, counters);
  auto latest = std::make_unique<Latest<heartbeat_t>>(subscriptions, "STATE");
  latest.reset();
  const heartbeat_t msg = numbered(1);
  bus.publish("STATE", &msg);
  pump(bus);  // must not touch the destroyed holder
  EXPECT_EQ(counters.messages_in, 1);
  EXPECT_EQ(counters.errors, 0);
}

TEST(Latest, ReadersInAnotherThreadSeeWholeMessages) {
  lcm::LCM bus("memq://");
  Counters counters;
  Subscriptions subscriptions(bus, counters);
  const Latest<heartbeat_t> latest(subscriptions, "STATE");
  constexpr int kMessages = 2000;
  std::atomic<bool> done{false};
  std::atomic<int> torn{0};
  std::thread reader([&] {
    int64_t last_count = 0;
    while (!done) {
      if (!latest.has()) continue;
      const heartbeat_t msg = latest.get();
      if (msg.service != "s" + std::to_string(msg.utime)) ++torn;  // fields from two messages
      const int64_t count = latest.count();
      if (count < last_count) ++torn;
      last_count = count;
    }
  });
  for (int i = 1; i <= kMessages; ++i) {
    const heartbeat_t msg = numbered(i);
    bus.publish("STATE", &msg);
    pump(bus);
  }
  done = true;
  reader.join();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(latest.count(), kMessages);
  EXPECT_EQ(latest.get().utime, kMessages);
}
