// Service test: the symmetry service as a pure function from log to log, through LCM's file
// provider (file://in?speed=0 in, file://out?mode=w out). The input log holds synthetic frames
// with known axes, a truncated message and an image with an unknown pixel format.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/run_service.hpp"

namespace syn = nudge::symmetry::synthetic;
namespace channel = nudge::bus::channel;

namespace {

using nudge::test::encode;
using nudge::test::LogWriter;
using nudge::test::run_from_log;

constexpr double kDeg = M_PI / 180.0;

struct Truth {
  double r, theta;
};

// Offsets of the lengths an encoded image_t from camera "mono" declares (fingerprint 8, utime 8,
// frame_id 8, the camera's length, "mono" and its NUL, width, height, row_stride, pixel_format).
constexpr size_t kCameraLengthOffset = 24;
constexpr size_t kSizeOffset = kCameraLengthOffset + 4 + 5 + 4 + 4 + 4 + 1;

void put_int32(std::vector<uint8_t>* bytes, size_t offset, int32_t value) {
  for (int i = 0; i < 4; ++i) (*bytes)[offset + i] = static_cast<uint8_t>(static_cast<uint32_t>(value) >> (24 - 8 * i));
}

// Frames with one upright bottle each, at known axes.
std::map<int64_t, Truth> write_input_log(const std::string& path) {
  LogWriter log(path);
  std::map<int64_t, Truth> truth;
  for (int i = 0; i < 6; ++i) {
    cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 210, 220));
    const Truth t{-60.0 + 25.0 * i, (-6.0 + 2.5 * i) * kDeg};
    syn::draw_shape(img, syn::bottle_profile(160, 30), t.r, t.theta, 0, cv::Scalar(40, 60, 90));
    const int64_t utime = 1000000 + 40000 * i;
    const int8_t format = i % 2 ? nudge::image_t::FORMAT_PNG : nudge::image_t::FORMAT_GRAY8;
    log.write(utime, channel::CAMERA, nudge::bus::to_message(img, format, utime, i, "mono"));
    truth[utime] = t;
    if (i == 2) {  // a truncated message: must be reported and skipped
      auto bytes = encode(nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, utime + 1, 99, "mono"));
      bytes.resize(bytes.size() / 2);
      log.raw(utime + 1, channel::CAMERA, bytes);
    }
    if (i == 3) {  // the camera string declares length 0: LCM 1.3.1's decode() throws on it
      auto bytes = encode(nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, utime + 1, 97, "mono"));
      put_int32(&bytes, kCameraLengthOffset, 0);
      log.raw(utime + 1, channel::CAMERA, bytes);
    }
    if (i == 5) {  // 114 bytes declaring a 2 GB image: refused before anything is allocated
      auto bytes = encode(nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, utime + 1, 96, "mono"));
      bytes.resize(114);
      put_int32(&bytes, kSizeOffset, 2000000000);
      log.raw(utime + 1, channel::CAMERA, bytes);
    }
    if (i == 4) {  // an unknown pixel format
      auto bad = nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, utime + 2, 98, "mono");
      bad.pixel_format = 42;
      log.write(utime + 2, channel::CAMERA, bad);
    }
  }
  return truth;
}

}  // namespace

TEST(SymmetryService, LogInLogOutMatchesTheKnownAxesAndSkipsBadMessages) {
  const std::string in = nudge::test::temp_path("symmetry_in.lcmlog");
  const auto truth = write_input_log(in);

  const auto run = run_from_log("nudge-symmetry", "--inputs CAMERA --lines 3 --dmin 10 --dmax 0 --theta-min -30 --theta-max 30",
                                in, nudge::test::temp_path("symmetry_out.lcmlog"));
  ASSERT_EQ(run.exit_code, 0) << run.command;
  std::map<int64_t, nudge::symmetry_lines_t> results;
  for (const auto& msg : nudge::test::messages_on<nudge::symmetry_lines_t>(run.output, channel::SYMMETRY))
    results[msg.utime] = msg;
  const int64_t errors_reported = nudge::test::last_heartbeat_errors(run.output);
  ASSERT_EQ(results.size(), truth.size()) << "one SYMMETRY message per good frame";
  EXPECT_EQ(errors_reported, 4)
      << "the truncated, zero-length camera, 2 GB and unknown-format messages are counted";
  for (const auto& [utime, t] : truth) {
    const auto& msg = results.at(utime);
    ASSERT_GE(msg.num_lines, 1);
    EXPECT_EQ(msg.width, 320);
    EXPECT_GT(msg.num_edges, 100);
    EXPECT_NEAR(msg.lines[0].r, t.r, 1.0) << "utime " << utime;
    EXPECT_NEAR(msg.lines[0].theta, t.theta, 1.0 * kDeg) << "utime " << utime;
  }
}

TEST(SymmetryService, ContoursOfTheTopLinesOnRequest) {
  const std::string in = nudge::test::temp_path("contours_in.lcmlog");
  const auto truth = write_input_log(in);
  const auto run = run_from_log("nudge-symmetry",
                                "--inputs CAMERA --lines 1 --dmin 10 --dmax 0 --theta-min -30 --theta-max 30"
                                " --contours 1 2>/dev/null",
                                in, nudge::test::temp_path("contours_out.lcmlog"));
  ASSERT_EQ(run.exit_code, 0) << run.command;
  int frames = 0;
  for (const auto& msg : nudge::test::messages_on<nudge::contours_t>(run.output, channel::CONTOURS)) {
    ++frames;
    ASSERT_EQ(msg.num_contours, 1);
    const auto& c = msg.contours[0];
    EXPECT_GT(c.num_left, 100);
    EXPECT_GT(c.num_right, 100);
    // Every contour point lies within the bottle's half-width (30 px) of the true axis.
    const Truth& t = truth.at(msg.utime);
    const double cx = 159.5, cy = 119.5;
    for (const auto* side : {&c.left, &c.right}) {
      for (const auto& p : *side) {
        const double offset = (p[0] - cx) * std::cos(t.theta) + (p[1] - cy) * std::sin(t.theta) - t.r;
        EXPECT_LE(std::fabs(offset), 33.0);
      }
    }
  }
  EXPECT_EQ(frames, static_cast<int>(truth.size()));
}

TEST(SymmetryService, BadFlagsAreRefusedWithAUsageError) {
  const std::string bin = nudge::test::bin_dir() + "/nudge-symmetry";
  for (const std::string args : {" --dmin 300 --dmax 100", " --theta-min -200", " --lines x", " --no-such-flag"})
    EXPECT_EQ(nudge::test::run_command(bin + args + " 2>/dev/null"), 2) << args;
}

// Issue 12: a log that ends in the middle of a message (a recorder killed, a disk that filled up)
// is played up to its last whole message; the service then ends as at the end of any log.
TEST(SymmetryService, ALogThatEndsMidMessageIsPlayedUpToItsLastWholeMessage) {
  const std::string in = nudge::test::temp_path("symmetry_cut_in.lcmlog");
  const auto truth = write_input_log(in);
  const auto size = std::filesystem::file_size(in);
  std::filesystem::resize_file(in, size - 60);  // inside the last message (the 114-byte one)
  const auto run = run_from_log("nudge-symmetry", "--inputs CAMERA --lines 3 --dmin 10 --dmax 0 --theta-min -30 --theta-max 30",
                                in, nudge::test::temp_path("symmetry_cut_out.lcmlog"));
  ASSERT_EQ(run.exit_code, 0) << run.command;
  EXPECT_EQ(nudge::test::messages_on<nudge::symmetry_lines_t>(run.output, channel::SYMMETRY).size(), truth.size());
  EXPECT_EQ(nudge::test::last_heartbeat_errors(run.output), 3) << "the cut message is not half-decoded";
}
