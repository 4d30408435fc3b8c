#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <sstream>

#include "nudge/atomic_file.hpp"
#include "nudge/bus_clock.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"

using namespace nudge;

namespace {
bool parse(Flags& flags, std::vector<std::string> args) {
  std::vector<char*> argv;
  static std::string program = "prog";
  argv.push_back(program.data());
  for (auto& a : args) argv.push_back(a.data());
  return flags.parse(static_cast<int>(argv.size()), argv.data());
}
}  // namespace

TEST(Flags, ParsesEveryKindAndKeepsPositionals) {
  std::string name = "x";
  int n = 1;
  double d = 0.5;
  bool on = false;
  std::vector<double> pair = {1, 2};
  Flags f("prog", "test");
  f.add_string("name", &name, "");
  f.add_int("n", &n, "");
  f.add_double("d", &d, "");
  f.add_bool("on", &on, "");
  f.add_doubles("pair", &pair, 2, "");
  ASSERT_TRUE(parse(f, {"a.png", "--name", "bob", "--n=7", "--d", "-2.5", "--on", "--pair", "30", "90", "b.png"}));
  EXPECT_EQ(name, "bob");
  EXPECT_EQ(n, 7);
  EXPECT_DOUBLE_EQ(d, -2.5);
  EXPECT_TRUE(on);
  EXPECT_EQ(pair, (std::vector<double>{30, 90}));
  EXPECT_EQ(f.positional(), (std::vector<std::string>{"a.png", "b.png"}));
  EXPECT_TRUE(f.given("n"));
  EXPECT_FALSE(f.given("zzz"));
}

TEST(Flags, BadValuesNameTheFlag) {
  int n = 0;
  double d = 0;
  Flags f("prog", "test");
  f.add_int("n", &n, "");
  f.add_double("d", &d, "");
  auto message = [&](std::vector<std::string> args) {
    try {
      parse(f, args);
    } catch (const FlagError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({"--n", "seven"}).find("--n"), std::string::npos);
  EXPECT_NE(message({"--d", "nan"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--d", "1e999"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--d"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--nope"}).find("--nope"), std::string::npos);
}

TEST(Json, EscapesAndNestsAndWritesNullForNonFinite) {
  JsonWriter j;
  j.begin_object();
  j.field("s", "a\"b\\c\n").field("n", 3).field("x", std::nan("")).key("arr").begin_array();
  j.value(1).value(true).begin_object().field("k", "v").end_object();
  j.end_array().end_object();
  EXPECT_EQ(j.str(), R"({"s":"a\"b\\c\n","n":3,"x":null,"arr":[1,true,{"k":"v"}]})");
}

TEST(AtomicFile, ReplacesContentsAndLeavesNoTemporaries) {
  const std::string path = testing::TempDir() + "/atomic_test.txt";
  write_file_atomically(path, "first");
  write_file_atomically(path, "second");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second");
  EXPECT_THROW(write_file_atomically("/nonexistent-dir/x.txt", "y"), std::runtime_error);
}

// ---------------------------------------------------------------- the bus clock

namespace {

// A wall clock the test moves by hand.
struct FakeWall {
  int64_t utime = 1700000000LL * 1000000LL;
  nudge::WallClock clock() {
    return [this] { return utime; };
  }
};

}  // namespace

TEST(BusClock, ParsesItsSourcesAndNamesTheChoicesOnError) {
  using nudge::ClockSource;
  EXPECT_EQ(nudge::parse_clock_source("auto", true), ClockSource::Log);
  EXPECT_EQ(nudge::parse_clock_source("auto", false), ClockSource::Wall);
  EXPECT_EQ(nudge::parse_clock_source("sim", false), ClockSource::Sim);
  EXPECT_EQ(nudge::parse_clock_source("log", false), ClockSource::Log);
  EXPECT_EQ(nudge::clock_source_name(ClockSource::Sim), "sim");
  try {
    nudge::parse_clock_source("moon", false);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("auto, wall, sim or log, not 'moon'"), std::string::npos) << e.what();
  }
}

TEST(BusClock, WallTimeMovesWithTheHostWhateverTheStamps) {
  FakeWall wall;
  nudge::BusClock clock(nudge::ClockSource::Wall, wall.clock());
  EXPECT_FALSE(clock.now());
  EXPECT_EQ(clock.on_message(5, nudge::Stamp::Sender), wall.utime);
  wall.utime += 1000;
  EXPECT_EQ(clock.on_timer(), wall.utime);
  EXPECT_EQ(clock.on_message(5, nudge::Stamp::Simulated), wall.utime);
  EXPECT_FALSE(clock.deadlines_on_message_time());
  EXPECT_EQ(clock.deadline_time(), wall.utime);
}

TEST(BusClock, SimTimeFollowsOnlyTheSimulatorAndNeverGoesBack) {
  FakeWall wall;
  nudge::BusClock clock(nudge::ClockSource::Sim, wall.clock());
  EXPECT_FALSE(clock.on_message(wall.utime, nudge::Stamp::Sender));  // a command's wall stamp
  EXPECT_FALSE(clock.on_timer());
  EXPECT_EQ(clock.on_message(40000, nudge::Stamp::Simulated), 40000);
  EXPECT_EQ(clock.on_message(20000, nudge::Stamp::Simulated), 40000);  // late: the clock stays
  EXPECT_EQ(clock.now(), 40000);
  // The supervisor beats in real time: its deadlines stay on the wall clock.
  EXPECT_EQ(clock.deadline_time(), wall.utime);
}

TEST(BusClock, LogTimeFollowsTheSendersStampsNotTheSimulator) {
  FakeWall wall;
  nudge::BusClock clock(nudge::ClockSource::Log, wall.clock());
  EXPECT_EQ(clock.on_message(3000000, nudge::Stamp::Sender), 3000000);
  EXPECT_FALSE(clock.on_message(9000000, nudge::Stamp::Simulated));
  EXPECT_FALSE(clock.on_timer());
  EXPECT_TRUE(clock.deadlines_on_message_time());
  EXPECT_EQ(clock.deadline_time(), 3000000);
  wall.utime += 5000000;  // the host's time does not matter
  EXPECT_EQ(clock.deadline_time(), 3000000);
}

TEST(LogTimeline, OriginFromTheFirstStampOrGiven) {
  nudge::LogTimeline simulated;  // stamps that look like simulated time count from 0
  EXPECT_DOUBLE_EQ(simulated.seconds(2500000), 2.5);
  EXPECT_EQ(simulated.origin(), 0);
  const int64_t recorded = 1700000000LL * 1000000LL;
  nudge::LogTimeline wall;  // wall-clock stamps count from the first one
  EXPECT_DOUBLE_EQ(wall.seconds(recorded), 0.0);
  EXPECT_DOUBLE_EQ(wall.seconds(recorded + 1500000), 1.5);
  nudge::LogTimeline given(1000000);
  EXPECT_DOUBLE_EQ(given.seconds(3000000), 2.0);
  // A wall-clock stamp after simulated ones is on another clock.
  EXPECT_THROW(simulated.seconds(recorded), std::invalid_argument);
  EXPECT_DOUBLE_EQ(simulated.seconds(3000000), 3.0);  // and the timeline is still usable
}

TEST(Pacer, RunsSimulatedTimeAtItsFactorAndFallsBehindWithoutRushing) {
  FakeWall wall;
  nudge::Pacer pacer(2.0, wall.clock());
  EXPECT_DOUBLE_EQ(pacer.target(0.0), 0.0);  // anchors
  wall.utime += 40000;                        // 40 ms of wall time: 80 ms simulated
  EXPECT_NEAR(pacer.target(0.0), 0.08, 1e-12);
  EXPECT_EQ(pacer.wait_ms(0.0078125, 0.0), 4);  // 7.8 ms simulated at twice real time: 3.9 ms
  EXPECT_EQ(pacer.wait_ms(5.0, 0.1), 20);       // never more than 20 ms
  EXPECT_EQ(pacer.wait_ms(0.1, 0.2), 0);        // already past
  wall.utime += 1000000;                      // a second later physics is still at 0.1 s
  EXPECT_DOUBLE_EQ(pacer.target(0.1), 0.1);   // re-anchored: no rush to catch up
  EXPECT_EQ(pacer.slips(), 1);
  wall.utime += 10000;
  EXPECT_NEAR(pacer.target(0.1), 0.12, 1e-12);
  EXPECT_THROW(nudge::Pacer(0.0), std::invalid_argument);
}
