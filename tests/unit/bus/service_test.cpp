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

}  // namespace

TEST(ServiceInProcess, HandlersRunOnAMemqBusPumpedByHandlePending) {
  lcm::LCM bus("memq://");
  Service service("echo", "test service");
  service.start(bus);
  install_echo(service);
  Probe probe(bus);

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
  lcm::LCM bus("memq://");
  Service service("echo", "test service");
  service.start(bus);
  install_echo(service);
  Probe probe(bus);

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
  EXPECT_EQ(hb.status, "checking");
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
