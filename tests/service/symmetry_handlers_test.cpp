// The symmetry service's handlers in-process: built on a memq:// bus the test owns, fed images,
// pumped with handle_pending(); what they publish is read with Latest. No sockets, no clock, no
// child process (the binary's log-to-log test is symmetry_service_test.cpp).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "nudge/bus/image.hpp"
#include "nudge/bus/latest.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "symmetry/handlers.hpp"

namespace syn = nudge::symmetry::synthetic;
using nudge::bus::Latest;
using nudge::bus::Service;

namespace {

constexpr double kDeg = M_PI / 180.0;

// An upright bottle whose axis is at (r, theta) about the image centre.
nudge::image_t bottle_image(double r, double theta, int64_t utime, int8_t format = nudge::image_t::FORMAT_GRAY8) {
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 210, 220));
  syn::draw_shape(img, syn::bottle_profile(160, 30), r, theta, 0, cv::Scalar(40, 60, 90));
  return nudge::bus::to_message(img, format, utime, static_cast<int32_t>(utime), "mono");
}

nudge::symmetry_service::Options mono_options() {
  nudge::symmetry_service::Options options;
  options.inputs = {"CAMERA"};
  options.params.num_lines = 3;
  options.params.dmin = 10;
  options.params.dmax = 0;
  options.params.theta_min_deg = -30;
  options.params.theta_max_deg = 30;
  options.edge.blur_sigma = 1.0;
  return options;
}

// A symmetry service on a bus of the test's own, with the test's end subscribed to its outputs.
struct InProcess {
  explicit InProcess(const nudge::symmetry_service::Options& options)
      : service("symmetry", "in-process test"),
        started((service.start(bus), true)),
        handlers(service, options),
        probe(bus, probe_counters),
        lines(probe, "SYMMETRY"),
        contours(probe, "CONTOURS") {}
  lcm::LCM bus{"memq://"};
  Service service;
  bool started;
  nudge::symmetry_service::Handlers handlers;
  nudge::bus::Counters probe_counters;
  nudge::bus::Subscriptions probe;
  Latest<nudge::symmetry_lines_t> lines;
  Latest<nudge::contours_t> contours;
};

}  // namespace

TEST(SymmetryHandlers, EveryImageGetsItsLinesAtTheKnownAxis) {
  InProcess run(mono_options());
  for (int i = 0; i < 3; ++i) {
    const double r = -40.0 + 30.0 * i, theta = (-5.0 + 4.0 * i) * kDeg;
    const int8_t format = i % 2 ? nudge::image_t::FORMAT_PNG : nudge::image_t::FORMAT_GRAY8;
    const nudge::image_t image = bottle_image(r, theta, 1000 + i, format);
    run.bus.publish("CAMERA", &image);
    EXPECT_EQ(run.service.handle_pending(), 2) << "the image and the lines it caused";
    ASSERT_EQ(run.lines.count(), i + 1);
    const nudge::symmetry_lines_t lines = run.lines.get();
    EXPECT_EQ(lines.utime, 1000 + i);
    EXPECT_EQ(lines.camera, "mono");
    ASSERT_GE(lines.num_lines, 1);
    EXPECT_NEAR(lines.lines[0].r, r, 1.0);
    EXPECT_NEAR(lines.lines[0].theta, theta, 1.0 * kDeg);
  }
  EXPECT_FALSE(run.contours.has()) << "contours only on request";
  EXPECT_EQ(run.service.counters().errors, 0);
}

TEST(SymmetryHandlers, BadImagesAreCountedAndSkipped) {
  InProcess run(mono_options());
  const nudge::image_t good = bottle_image(0, 0, 10);
  auto truncated = nudge::test::encode(good);
  truncated.resize(truncated.size() / 2);
  run.bus.publish("CAMERA", truncated.data(), static_cast<unsigned>(truncated.size()));
  nudge::image_t unknown_format = good;
  unknown_format.pixel_format = 42;
  run.bus.publish("CAMERA", &unknown_format);
  run.bus.publish("CAMERA", &good);
  run.service.handle_pending();
  EXPECT_EQ(run.service.counters().errors, 2);
  EXPECT_EQ(run.lines.count(), 1) << "the good image after the bad ones";
  EXPECT_EQ(run.lines.get().utime, 10);
}

TEST(SymmetryHandlers, ContoursOfTheTopLinesOnRequest) {
  auto options = mono_options();
  options.params.num_lines = 1;
  options.contours = 1;
  InProcess run(options);
  const double r = 20, theta = 4 * kDeg;
  const nudge::image_t image = bottle_image(r, theta, 77);
  run.bus.publish("CAMERA", &image);
  run.service.handle_pending();
  ASSERT_TRUE(run.contours.has());
  const nudge::contours_t msg = run.contours.get();
  EXPECT_EQ(msg.utime, 77);
  ASSERT_EQ(msg.num_contours, 1);
  EXPECT_GT(msg.contours[0].num_left, 100);
  EXPECT_GT(msg.contours[0].num_right, 100);
  for (const auto* side : {&msg.contours[0].left, &msg.contours[0].right})
    for (const auto& p : *side)  // within the bottle's half-width (30 px) of the axis
      EXPECT_LE(std::fabs((p[0] - 159.5) * std::cos(theta) + (p[1] - 119.5) * std::sin(theta) - r), 33.0);
}
