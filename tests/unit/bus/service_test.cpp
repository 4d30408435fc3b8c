// The service shell on an in-process bus (LCM's memq:// provider): handlers built in the test's
// process, messages published to them and pumped with handle_pending(), no sockets, no clock.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <stdexcept>
#include <string>
#include <vector>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/latest.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/timing.hpp"

using nudge::heartbeat_t;
using nudge::bus::Latest;
using nudge::bus::Service;
using nudge::bus::Subscriptions;

namespace {

heartbeat_t heartbeat(int64_t utime, const std::string& status) {
  heartbeat_t hb{};
  hb.utime = utime;
  hb.service = "test";
  hb.status = status;
  return hb;
}

// A service whose handler echoes every IN message on OUT with its status upper-cased, and
// refuses (throws on) the status "bad".
void install_echo(Service& service) {
  service.subscriptions().subscribe<heartbeat_t>("IN", [&service](const heartbeat_t& msg, const std::string&) {
    if (msg.status == "bad") throw std::invalid_argument("status 'bad' refused");
    heartbeat_t out = msg;
    for (char& c : out.status) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    service.publish("OUT", out);
  });
}

// The test's end of the bus: what the service publishes.
struct Probe {
  explicit Probe(lcm::LCM& lcm) : subscriptions(lcm, counters), out(subscriptions, "OUT"),
                                   heartbeats(subscriptions, nudge::bus::channel::HEARTBEAT) {}
  nudge::bus::Counters counters;
  Subscriptions subscriptions;
  Latest<heartbeat_t> out, heartbeats;
};

// The echo service started on an in-process bus of its own, and the test's probe on that bus.
struct EchoOnMemq {
  EchoOnMemq() : started((service.start(bus), install_echo(service), true)), probe(bus) {}
  lcm::LCM bus{"memq://"};
  Service service{"echo", "test service"};
  bool started;
  Probe probe;
};

// The heartbeat `service` publishes as if its clock read `utime`, as `probe` hears it.
heartbeat_t heartbeat_at(Service& service, Probe& probe, int64_t utime) {
  service.publish_heartbeat_at(utime);
  service.handle_pending();
  return probe.heartbeats.get();
}

// An echo that refused a message (now: the wall clock then): DEGRADED, naming the refusal.
void expect_degraded_by_a_refused_message(EchoOnMemq& echo, int64_t now) {
  const heartbeat_t refused = heartbeat(1, "bad");
  echo.bus.publish("IN", &refused);
  echo.service.handle_pending();
  const heartbeat_t hb = heartbeat_at(echo.service, echo.probe, now);
  EXPECT_EQ(hb.state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_NE(hb.status.find("status 'bad' refused"), std::string::npos) << hb.status;
}

}  // namespace

TEST(ServiceInProcess, HandlersRunOnAMemqBusPumpedByHandlePending) {
  EchoOnMemq echo;
  auto& [bus, service, started, probe] = echo;

  const heartbeat_t first = heartbeat(10, "one"), second = heartbeat(20, "two");
  bus.publish("IN", &first);
  bus.publish("IN", &second);
  // Two inputs, then the two replies the handler published onto the same bus.
  EXPECT_EQ(service.handle_pending(), 4);
  ASSERT_EQ(probe.out.count(), 2);
  EXPECT_EQ(probe.out.get().status, "TWO");
  EXPECT_EQ(probe.out.get().utime, 20);
  EXPECT_EQ(service.counters().messages_in, 2);
  EXPECT_EQ(service.counters().messages_out, 2);
  EXPECT_EQ(service.handle_pending(), 0) << "nothing left: no wait, no clock";
}

TEST(ServiceInProcess, BadInputsAreCountedAndTheServiceKeepsHandling) {
  EchoOnMemq echo;
  auto& [bus, service, started, probe] = echo;

  const std::vector<uint8_t> garbage = {1, 2, 3};
  bus.publish("IN", garbage.data(), static_cast<unsigned>(garbage.size()));  // does not decode
  const heartbeat_t refused = heartbeat(1, "bad"), good = heartbeat(2, "good");
  bus.publish("IN", &refused);
  bus.publish("IN", &good);
  service.handle_pending();
  EXPECT_EQ(service.counters().errors, 2);
  EXPECT_EQ(service.counters().messages_in, 3);
  ASSERT_EQ(probe.out.count(), 1);
  EXPECT_EQ(probe.out.get().status, "GOOD");

  service.set_status("checking");
  service.publish_heartbeat();
  service.handle_pending();
  ASSERT_TRUE(probe.heartbeats.has());
  const heartbeat_t hb = probe.heartbeats.get();
  EXPECT_EQ(hb.service, "echo");
  EXPECT_EQ(hb.instance, "echo") << "without a command line the instance is the service's name";
  EXPECT_EQ(hb.state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_EQ(hb.errors, 2);
  EXPECT_EQ(hb.messages_in, 3);
  // The service's own status first, then what went wrong (issue 12: the status was always empty).
  EXPECT_EQ(hb.status.rfind("checking; 2 errors, last: skipped a ", 0), 0u) << hb.status;
}

TEST(ServiceInProcess, FlagsStillApplyWhenTheTransportIsInjected) {
  lcm::LCM bus("memq://");
  Service service("echo", "test service");
  std::vector<std::string> args = {"nudge-echo", "--instance", "left"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  ASSERT_TRUE(service.parse(static_cast<int>(argv.size()), argv.data()));
  service.start(bus);
  Probe probe(bus);
  service.publish_heartbeat();
  service.handle_pending();
  ASSERT_TRUE(probe.heartbeats.has());
  EXPECT_EQ(probe.heartbeats.get().instance, "left");
  EXPECT_EQ(probe.heartbeats.get().state + 0, heartbeat_t::STATE_RUNNING + 0);
}

TEST(ServiceInProcess, ASeparateOutputReceivesThePublications) {
  lcm::LCM in("memq://"), out("memq://");
  Service service("echo", "test service");
  service.start(in, &out);
  install_echo(service);
  Probe on_input(in), on_output(out);
  const heartbeat_t msg = heartbeat(5, "x");
  in.publish("IN", &msg);
  EXPECT_EQ(service.handle_pending(), 1);
  EXPECT_EQ(out.handleTimeout(0), 1);
  EXPECT_EQ(on_output.out.count(), 1);
  EXPECT_FALSE(on_input.out.has());
}

TEST(ServiceInProcess, HandlePendingStopsAtItsLimitWhenAHandlerFeedsItself) {
  lcm::LCM bus("memq://");
  Service service("loop", "test service");
  service.start(bus);
  service.subscriptions().subscribe<heartbeat_t>("IN", [&service](const heartbeat_t& msg, const std::string&) {
    service.publish("IN", msg);
  });
  const heartbeat_t msg = heartbeat(1, "again");
  bus.publish("IN", &msg);
  EXPECT_EQ(service.handle_pending(25), 25);
  EXPECT_TRUE(service.spin_once(0)) << "the 26th is still queued";
}

TEST(ServiceInProcess, UrlsGivenProgrammatically) {
  Service service("echo", "test service");
  service.start("memq://", "");
  install_echo(service);
  Probe probe(service.input());
  const heartbeat_t msg = heartbeat(7, "url");
  service.input().publish("IN", &msg);
  service.handle_pending();
  ASSERT_TRUE(probe.out.has());
  EXPECT_EQ(probe.out.get().status, "URL");
}

TEST(ServiceInProcess, ABadUrlOrNoStartIsAClearError) {
  Service service("echo", "test service");
  EXPECT_THROW(service.spin_once(), std::logic_error);
  try {
    service.start("nosuchprovider://x", "");
    FAIL() << "a bad URL was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://x"), std::string::npos) << e.what();
  }
}

// ---- drops, recovery and silent peers (issue 12) ----------------------------------------------

namespace {
nudge::image_t frame(int64_t frame_id) {
  nudge::image_t image{};
  image.frame_id = frame_id;
  image.camera = "left";
  image.width = image.height = image.row_stride = 1;
  image.pixel_format = nudge::image_t::FORMAT_GRAY8;
  image.data = {7};
  image.size = 1;
  return image;
}
}  // namespace

TEST(ServiceInProcess, FrameIdGapsAreCountedPerChannelAndShownInTheHeartbeat) {
  lcm::LCM bus("memq://");
  Service service("sink", "test service");
  service.start(bus);
  int handled = 0;
  service.subscriptions().subscribe<nudge::image_t>("CAM", [&](const nudge::image_t&, const std::string&) { ++handled; });
  Probe probe(bus);
  for (int64_t id : {0, 1, 4, 5, 9}) {  // 2, 3, 6, 7, 8 lost on the way
    const nudge::image_t image = frame(id);
    bus.publish("CAM", &image);
  }
  const nudge::image_t restarted = frame(0);  // a source that restarts is not a loss
  bus.publish("CAM", &restarted);
  service.handle_pending();
  EXPECT_EQ(handled, 6);
  EXPECT_EQ(service.counters().missed, 5);
  const auto gaps = service.counters().gaps();
  ASSERT_EQ(gaps.count("CAM"), 1u);
  EXPECT_EQ(gaps.at("CAM").received, 6);
  EXPECT_EQ(gaps.at("CAM").missed, 5);
  EXPECT_EQ(gaps.at("CAM").restarts, 1);

  const int64_t now = nudge::wall_utime();
  const heartbeat_t lossy = heartbeat_at(service, probe, now);
  ASSERT_TRUE(probe.heartbeats.has());
  EXPECT_EQ(lossy.state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_NE(lossy.status.find("CAM missed 5 of 11"), std::string::npos) << lossy.status;

  // No new loss for longer than the hold: RUNNING again, the totals still in the status.
  const heartbeat_t held = heartbeat_at(service, probe, now + nudge::bus::kDegradedHoldUs + 1);
  EXPECT_EQ(held.state + 0, heartbeat_t::STATE_RUNNING + 0);
  EXPECT_NE(held.status.find("CAM missed 5 of 11"), std::string::npos);
}

TEST(ServiceInProcess, ADegradedHeartbeatRecoversWhenInputsAreGoodAgain) {
  EchoOnMemq echo;
  auto& [bus, service, started, probe] = echo;
  const int64_t now = nudge::wall_utime();
  expect_degraded_by_a_refused_message(echo, now);

  const heartbeat_t good = heartbeat(2, "good");
  bus.publish("IN", &good);
  service.handle_pending();
  EXPECT_EQ(heartbeat_at(service, probe, now + nudge::bus::kDegradedHoldUs / 2).state + 0, heartbeat_t::STATE_DEGRADED + 0)
      << "still within the hold";
  const heartbeat_t hb = heartbeat_at(service, probe, now + nudge::bus::kDegradedHoldUs + 1);
  EXPECT_EQ(hb.state + 0, heartbeat_t::STATE_RUNNING + 0);
  EXPECT_EQ(hb.errors, 1) << "the count stays: it is a total";
}

TEST(ServiceInProcess, AWatchedServiceThatFallsSilentIsNamedUntilItIsHeardAgain) {
  lcm::LCM bus("memq://");
  Service service("monitor", "test service");
  service.start(bus);
  service.watch_heartbeats({"camera"});
  Probe probe(bus);
  heartbeat_t camera = heartbeat(1, "");
  camera.service = camera.instance = "camera";
  camera.pid = 999999;
  heartbeat_t arm = camera;
  arm.service = arm.instance = "arm";  // not watched
  bus.publish(nudge::bus::channel::HEARTBEAT, &camera);
  bus.publish(nudge::bus::channel::HEARTBEAT, &arm);
  service.handle_pending();
  const int64_t heard = nudge::wall_utime();
  EXPECT_TRUE(service.check_heartbeats(heard).empty());

  const auto silent = service.check_heartbeats(heard + nudge::bus::kSilentAfterUs + 500000);
  ASSERT_EQ(silent.size(), 1u);
  EXPECT_EQ(silent[0].source, "camera");
  EXPECT_GT(silent[0].seconds, 2.5);
  EXPECT_LT(silent[0].seconds, 3.5);
  const heartbeat_t hb = heartbeat_at(service, probe, heard + 3000000);
  EXPECT_EQ(hb.state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_NE(hb.status.find("camera silent for"), std::string::npos) << hb.status;

  bus.publish(nudge::bus::channel::HEARTBEAT, &camera);  // heard again
  service.handle_pending();
  EXPECT_TRUE(service.check_heartbeats(nudge::wall_utime()).empty());
  camera.state = heartbeat_t::STATE_STOPPING;  // a goodbye: then silence is expected
  bus.publish(nudge::bus::channel::HEARTBEAT, &camera);
  service.handle_pending();
  EXPECT_TRUE(service.check_heartbeats(nudge::wall_utime() + 60000000).empty());
}

// A camera whose frames stop while its process lives (a hung driver, a video file at its end):
// its heartbeats say nothing, so the receiving service watches the stream itself.
TEST(ServiceInProcess, AStreamThatStopsIsNamedDegradedUntilItsFramesReturn) {
  lcm::LCM bus("memq://");
  Service service("symmetry", "test service");
  service.start(bus);
  service.watch_streams({"CAM"});
  Probe probe(bus);
  nudge::image_t frame{};
  bus.publish("CAM", &frame);
  service.handle_pending();
  const int64_t heard = nudge::wall_utime();
  EXPECT_TRUE(service.check_streams(heard).empty());
  EXPECT_EQ(heartbeat_at(service, probe, heard).state + 0, heartbeat_t::STATE_RUNNING + 0);

  const auto quiet = service.check_streams(heard + nudge::bus::kStreamSilentAfterUs + 500000);
  ASSERT_EQ(quiet.size(), 1u);
  EXPECT_EQ(quiet[0].channel, "CAM");
  const heartbeat_t silent = heartbeat_at(service, probe, heard + 3000000);
  EXPECT_EQ(silent.state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_NE(silent.status.find("CAM silent for 3."), std::string::npos) << silent.status;

  bus.publish("CAM", &frame);  // the frames return
  service.handle_pending();
  const int64_t back = nudge::wall_utime();
  EXPECT_TRUE(service.check_streams(back + 100000).empty());
  const heartbeat_t back_again = heartbeat_at(service, probe, back + 100000);
  EXPECT_EQ(back_again.status.find("CAM silent"), std::string::npos) << back_again.status;
  EXPECT_EQ(back_again.state + 0, heartbeat_t::STATE_DEGRADED + 0)
      << "DEGRADED for kDegradedHoldUs after the silence, RUNNING after (integration_stalled_stream)";
}

TEST(StreamWatch, ASlowStreamGetsFourOfItsIntervalsAndAClockThatGoesBackRestartsIt) {
  nudge::bus::StreamWatch watch;
  for (int i = 0; i < 5; ++i) watch.on_message("SLOW", i * 2000000);  // 0.5 Hz
  EXPECT_TRUE(watch.silent(8000000 + 3000000).empty()) << "1.5 intervals late: not yet";
  EXPECT_EQ(watch.silent(8000000 + 8500000).size(), 1u);
  // The clock goes back (a replayed log restarted): not silence, and the next message restarts it.
  EXPECT_TRUE(watch.silent(1000).empty());
  watch.on_message("SLOW", 2000);
  EXPECT_TRUE(watch.silent(2000 + 2000000).empty());
  EXPECT_EQ(watch.silent(2000 + nudge::bus::kStreamSilentAfterUs + 1).size(), 1u);
  EXPECT_EQ(nudge::bus::describe(watch.silent(2000 + 3100000)), "SLOW silent for 3.1 s");
}

// A wall clock stepped back (NTP, a restarted log's stamps) must not hold DEGRADED until it
// catches up with the last problem: the hold restarts from now.
TEST(ServiceInProcess, AClockThatGoesBackRestartsTheDegradedHold) {
  EchoOnMemq echo;
  auto& [bus, service, started, probe] = echo;
  const int64_t now = nudge::wall_utime();
  expect_degraded_by_a_refused_message(echo, now);
  const int64_t hour_back = now - 3600LL * 1000000;
  EXPECT_EQ(heartbeat_at(service, probe, hour_back).state + 0, heartbeat_t::STATE_DEGRADED + 0);
  EXPECT_EQ(heartbeat_at(service, probe, hour_back + nudge::bus::kDegradedHoldUs + 1).state + 0,
            heartbeat_t::STATE_RUNNING + 0);
}
