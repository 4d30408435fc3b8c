#include <gtest/gtest.h>

#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <future>
#include <stdexcept>
#include <sstream>
#include <thread>

#include "nudge/atomic_file.hpp"
#include "nudge/bus_clock.hpp"
#include "nudge/flags.hpp"
#include "nudge/image_header.hpp"
#include "nudge/json.hpp"
#include "nudge/memory.hpp"
#include "nudge/worker.hpp"
#include "nudge/yaml_file.hpp"

using namespace nudge;

namespace {
bool parse(Flags& flags, std::vector<std::string> args) {
  std::vector<char*> argv;
  static std::string program = "prog";
  argv.push_back(program.data());
  for (auto& a : args) argv.push_back(a.data());
  return flags.parse(static_cast<int>(argv.size()), argv.data());
}

// The calling thread's minor page faults while a fresh block of `bytes` is allocated, every page
// of it written, and freed.
long faults_of_a_written_block(size_t bytes) {
  rusage before{}, after{};
  getrusage(RUSAGE_THREAD, &before);
  auto* block = static_cast<volatile char*>(std::malloc(bytes));
  for (size_t i = 0; i < bytes; i += 4096) block[i] = 1;
  std::free(const_cast<char*>(block));
  getrusage(RUSAGE_THREAD, &after);
  return after.ru_minflt - before.ru_minflt;
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

namespace {
// A PNG's signature, IHDR chunk (CRC not checked by the header reader) and IEND chunk.
std::vector<uint8_t> png_header(uint32_t width, uint32_t height, bool with_end) {
  std::vector<uint8_t> b = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  for (uint32_t v : {width, height})
    for (int shift = 24; shift >= 0; shift -= 8) b.push_back(static_cast<uint8_t>(v >> shift));
  b.insert(b.end(), {8, 0, 0, 0, 0, 0, 0, 0, 0});  // depth, colour, compression, filter, interlace, CRC
  b.insert(b.end(), 20, 0);                         // stands for the IDAT chunks
  if (with_end) b.insert(b.end(), {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82});
  return b;
}
// SOI, an APP0 segment, SOF0 with the size, SOS, scan bytes (with an escaped FF 00), EOI.
std::vector<uint8_t> jpeg_bytes(uint16_t width, uint16_t height, bool with_end) {
  std::vector<uint8_t> b = {0xFF, 0xD8, 0xFF, 0xE0, 0, 4, 'J', 'F'};
  b.insert(b.end(), {0xFF, 0xC0, 0, 11, 8, static_cast<uint8_t>(height >> 8), static_cast<uint8_t>(height),
                     static_cast<uint8_t>(width >> 8), static_cast<uint8_t>(width), 1, 1, 0x11, 0});
  b.insert(b.end(), {0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 63, 0, 0x12, 0xFF, 0x00, 0x34, 0xFF, 0xD0, 0x56});
  if (with_end) b.insert(b.end(), {0xFF, 0xD9});
  return b;
}
}  // namespace

TEST(ImageHeader, ReadsPngAndJpegSizesWithoutDecoding) {
  const auto png = png_header(640, 480, true);
  const ImageHeader p = read_image_header(png.data(), png.size());
  EXPECT_EQ(p.format, ImageHeader::Format::Png);
  EXPECT_EQ(p.width, 640);
  EXPECT_EQ(p.height, 480);
  EXPECT_TRUE(p.complete);
  EXPECT_EQ(check_compressed_image(png.data(), png.size()), "");

  const auto jpeg = jpeg_bytes(1280, 960, true);
  const ImageHeader j = read_image_header(jpeg.data(), jpeg.size());
  EXPECT_EQ(j.format, ImageHeader::Format::Jpeg);
  EXPECT_EQ(j.width, 1280);
  EXPECT_EQ(j.height, 960);
  EXPECT_TRUE(j.complete);
  EXPECT_EQ(check_compressed_image(jpeg.data(), jpeg.size()), "");
}

TEST(ImageHeader, RefusesHugeDeclaredSizes) {
  const auto png = png_header(20000, 20000, true);  // the 389 KB PNG of issue 12 has this header
  const std::string problem = check_compressed_image(png.data(), png.size());
  EXPECT_NE(problem.find("20000x20000"), std::string::npos) << problem;
  const auto zero = png_header(0, 10, true);
  EXPECT_NE(check_compressed_image(zero.data(), zero.size()).find("0x10"), std::string::npos);
  const auto jpeg = jpeg_bytes(65535, 65535, true);
  EXPECT_NE(check_compressed_image(jpeg.data(), jpeg.size()).find("65535x65535"), std::string::npos);
  EXPECT_EQ(check_compressed_image(jpeg.data(), jpeg.size(), int64_t{65535} * 65535), "");
  // Two 32-bit dimensions whose product overflows an int64 (found by fuzzing): still refused.
  const auto vast = png_header(2701197311u, 4294967295u, true);
  EXPECT_NE(check_compressed_image(vast.data(), vast.size()).find("more than"), std::string::npos);
}

TEST(ImageHeader, RefusesTruncatedAndForeignData) {
  const auto png = png_header(64, 64, false);
  EXPECT_NE(check_compressed_image(png.data(), png.size()).find("truncated"), std::string::npos);
  const auto jpeg = jpeg_bytes(64, 64, false);
  EXPECT_NE(check_compressed_image(jpeg.data(), jpeg.size()).find("truncated"), std::string::npos);
  for (size_t cut = 0; cut < 20; ++cut)  // cut inside the header: never a size read past the end
    EXPECT_NE(check_compressed_image(jpeg.data(), cut), "") << cut;
  const std::vector<uint8_t> text = {'h', 'e', 'l', 'l', 'o'};
  EXPECT_NE(check_compressed_image(text.data(), text.size()).find("not a PNG or JPEG"), std::string::npos);
  EXPECT_NE(check_compressed_image(nullptr, 0), "");
}

// ---------------------------------------------------------------------------------------------
// YAML configuration files (yaml-cpp, not cv::FileStorage, which loops for ever on some inputs)

namespace {
// The error parse_yaml gives for `text`, or "" when it parses.
std::string yaml_error(const std::string& text) {
  try {
    parse_yaml(text, "bad.yaml", "test");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(YamlFile, ReadsOpenCVsHeaderTagsAndNumbers) {
  // As cv::FileStorage writes a matrix: the `%YAML:1.0` directive, a tag, `0.` and `1.`.
  const YAML::Node root = parse_yaml(
      "%YAML:1.0\n---\nK: !!opencv-matrix\n   rows: 1\n   cols: 3\n   dt: d\n"
      "   data: [ 5.7941125496954282e+02, 0., 1. ]\nname: \"3\"\nempty:\ntilde: ~\n",
      "rig.yaml", "test");
  const auto K = yaml_field(root, "K");
  ASSERT_TRUE(K.has_value());
  EXPECT_EQ(yaml_int(*yaml_field(*K, "rows")), 1);
  EXPECT_EQ(yaml_text(*yaml_field(*K, "dt")), "d");
  std::vector<double> data;
  const YAML::Node items = *yaml_field(*K, "data");
  for (const YAML::Node& item : items) data.push_back(yaml_number(item).value_or(-1));
  EXPECT_EQ(data, (std::vector<double>{579.41125496954282, 0, 1}));
  EXPECT_EQ(yaml_text(*yaml_field(root, "name")), "3") << "a quoted number is text";
  EXPECT_FALSE(yaml_int(*yaml_field(root, "name")).has_value());
  EXPECT_FALSE(yaml_field(root, "empty").has_value()) << "a null value counts as missing, as in OpenCV";
  EXPECT_FALSE(yaml_field(root, "tilde").has_value());
  EXPECT_FALSE(yaml_field(root, "absent").has_value());
  EXPECT_FALSE(yaml_field(*yaml_field(*K, "rows"), "x").has_value()) << "a scalar has no fields";
  EXPECT_EQ(yaml_keys(root), (std::vector<std::string>{"K", "name", "empty", "tilde"}));
}

TEST(YamlFile, TypesScalarsAsOpenCVDoes) {
  const auto scalar = [](const std::string& text) { return YAML::Load("v: " + text)["v"]; };
  EXPECT_EQ(yaml_int(scalar("-42")), -42);
  EXPECT_EQ(yaml_int(scalar("+7")), 7);
  EXPECT_FALSE(yaml_int(scalar("4.0")).has_value());
  EXPECT_FALSE(yaml_int(scalar("99999999999")).has_value()) << "beyond an int";
  EXPECT_EQ(yaml_number(scalar("1.")), 1.0);
  EXPECT_EQ(yaml_number(scalar(".5")), 0.5);
  EXPECT_EQ(yaml_number(scalar("+2.5e-1")), 0.25);
  EXPECT_EQ(yaml_number(scalar("-3")), -3.0);
  EXPECT_TRUE(std::isinf(*yaml_number(scalar(".Inf"))));
  EXPECT_LT(*yaml_number(scalar("-.inf")), 0);
  EXPECT_TRUE(std::isnan(*yaml_number(scalar(".Nan"))));
  for (const char* text : {"abc", "1.2.3", "0x10", "inf", "nan", "1e999", "+-1", "+", "'1.5'", "12abc"}) {
    EXPECT_FALSE(yaml_number(scalar(text)).has_value()) << text;
    EXPECT_TRUE(yaml_text(scalar(text)).has_value()) << text;
  }
  EXPECT_FALSE(yaml_text(scalar("[1, 2]")).has_value());
  EXPECT_FALSE(yaml_number(scalar("{a: 1}")).has_value());
}

TEST(YamlFile, MalformedTextIsAnErrorNamingTheSourceAndLine) {
  // cv::FileStorage loops for ever on the first (found by fuzz_workspace).
  const std::string hang = "%YAML:1.0\n---a%YAML:1.0\n-#e \n --\nr flagstool_l#en The a";
  for (const std::string& text : {std::string("%YAML:1.0\nobjects: [1, 2\n"), std::string("a: b: c\n"),
                                  std::string("a: [1, 2]]\n"), std::string("a:\n\tb: 1\n"),
                                  std::string("a: *nowhere\n"), std::string(64000, '[')}) {
    const std::string error = yaml_error(text);
    EXPECT_EQ(error.rfind("bad.yaml: not a valid test file", 0), 0u) << text.substr(0, 40) << " -> " << error;
  }
  // The hang input is YAML to yaml-cpp (a plain scalar): it returns, and the readers refuse it
  // for its missing fields (geometry_test, robot_workspace_tests, sim_test).
  EXPECT_TRUE(parse_yaml(hang, "hang.yaml", "test").IsScalar());
  // An alias may point back into its own node: the readers look fields up by name, never walk.
  EXPECT_TRUE(parse_yaml("&a [*a]", "cycle.yaml", "test").IsSequence());
}

TEST(YamlFile, FilesAreReadWholeOrRefusedNamingThem) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/yaml_file_test.yaml";
  std::ofstream(path) << "%YAML:1.0\n---\na: 1\n";
  EXPECT_EQ(yaml_int(*yaml_field(read_yaml_file(path, "test"), "a")), 1);
  try {
    read_yaml_file(dir + "/no_such.yaml", "workspace");
    FAIL() << "a missing file read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/no_such.yaml: cannot open workspace file");
  }
  std::ofstream(path) << std::string(kMaxYamlFileBytes + 1, '#');
  try {
    read_yaml_file(path, "scene");
    FAIL() << "a file beyond the limit read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": larger than a scene file can be"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

// A still-sized image freed and allocated again comes back from the heap, its pages already
// there: no page fault per page as a fresh map would take (docs/benchmarks.md: on a virtual
// machine these faults were half a motion segmentation's time).
TEST(Memory, AFreedStillSizedBlockIsReusedWithoutPageFaults) {
  if (!keep_large_buffers_for_reuse()) GTEST_SKIP() << "the allocator is not glibc's (a sanitizer's): nothing to set";
  EXPECT_TRUE(keep_large_buffers_for_reuse());  // again: the same settings
  constexpr size_t kStill = 1280 * 960 * 3;
  constexpr long kPages = kStill / 4096;
  faults_of_a_written_block(kStill);  // the heap grows to hold it once
  EXPECT_LT(faults_of_a_written_block(kStill), kPages / 10);
  EXPECT_LT(faults_of_a_written_block(kStill), kPages / 10);
}

// Every task on the one thread, never the caller's, in the order given; a task's exception reaches
// its future and the worker goes on; the tasks queued when it is destroyed still run.
TEST(Worker, RunsEveryTaskInOrderOnItsOneThread) {
  std::vector<int> order;
  std::vector<std::thread::id> threads;
  std::atomic<int> after_destruction{0};
  {
    Worker worker;
    std::vector<std::future<void>> done;
    for (int i = 0; i < 20; ++i)
      done.push_back(worker.run([&, i] {
        order.push_back(i);
        threads.push_back(std::this_thread::get_id());
      }));
    std::future<void> failed = worker.run([] { throw std::runtime_error("task failed"); });
    for (auto& d : done) d.get();
    EXPECT_THROW(failed.get(), std::runtime_error);
    worker.run([&] { order.push_back(20); }).get();
    for (int i = 0; i < 5; ++i) worker.run([&] { ++after_destruction; });
    EXPECT_EQ(threads.front(), worker.id());
  }
  EXPECT_EQ(after_destruction.load(), 5) << "queued tasks run before the worker is gone";
  ASSERT_EQ(order.size(), 21u);
  for (int i = 0; i <= 20; ++i) EXPECT_EQ(order[i], i);
  for (const auto& id : threads) {
    EXPECT_EQ(id, threads.front());
    EXPECT_NE(id, std::this_thread::get_id());
  }
}

// A scope left early (an exception) still waits for the task that uses its locals; a deferred
// task that never ran is not run by it.
TEST(Worker, WaitOnExitWaitsForTheRunningTaskButRunsNoDeferredOne) {
  Worker worker;
  std::atomic<bool> finished{false};
  try {
    std::future<void> task;
    const WaitOnExit joined{task};
    task = worker.run([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      finished = true;
    });
    throw std::runtime_error("left early");
  } catch (const std::runtime_error&) {
    EXPECT_TRUE(finished.load()) << "the scope waited for the task";
  }
  bool ran = false;
  {
    std::future<void> deferred = std::async(std::launch::deferred, [&] { ran = true; });
    const WaitOnExit joined{deferred};
  }
  EXPECT_FALSE(ran);
}
