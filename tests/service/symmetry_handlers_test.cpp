// The symmetry service's handlers in-process: built on a memq:// bus the test owns, fed images,
// pumped with handle_pending(); what they publish is read with Latest. No sockets, no clock, no
// child process (the binary's log-to-log test is symmetry_service_test.cpp).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "nudge/bus/image.hpp"
#include "nudge/bus/latest.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"
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

// What a fresh service publishes on SYMMETRY_RIGHT for one right-camera image (no error counted).
nudge::symmetry_lines_t right_lines_of(const nudge::symmetry_service::Options& options, const cv::Mat& img) {
  InProcess run(options);
  Latest<nudge::symmetry_lines_t> right(run.probe, "SYMMETRY_RIGHT");
  nudge::image_t image = nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, 1, 1, "right");
  run.bus.publish("CAMERA_RIGHT", &image);
  run.service.handle_pending();
  EXPECT_EQ(run.service.counters().errors, 0);
  return right.get();
}

// Lines within reach for a level 320x240 camera (f 300 px) 0.3 m above the table, one line kept,
// the reach 5 m around the place each test sets.
nudge::symmetry_service::Options::Reach level_reach() {
  nudge::symmetry_service::Options::Reach reach;
  for (nudge::geometry::Camera* camera : {&reach.rig.left, &reach.rig.right}) {
    camera->width = 320;
    camera->height = 240;
    camera->K << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1;
  }
  reach.table.normal = Eigen::Vector3d(0, -1, 0);
  reach.table.offset = 0.3;
  reach.radius = 5.0;
  reach.keep = 1;
  return reach;
}

// Two bottles in a right-camera image: the strongest (`strongest_height` px tall, leaning
// `strongest_tilt`) at r = 60 and an upright one, 110 px tall, at r = -80.
cv::Mat two_bottles(double strongest_tilt, int strongest_height = 160) {
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 210, 220));
  syn::draw_shape(img, syn::bottle_profile(strongest_height, 30), 60, strongest_tilt, 0, cv::Scalar(40, 60, 90));
  syn::draw_shape(img, syn::bottle_profile(110, 30), -80, 0, 0, cv::Scalar(40, 60, 90));
  return img;
}

// The right camera's options for two_bottles: no pairs across the two, only their own lines.
nudge::symmetry_service::Options two_bottle_options() {
  nudge::symmetry_service::Options options = mono_options();
  options.inputs = {"CAMERA_RIGHT"};
  options.params.dmax = 70;
  return options;
}

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

// With the upright check (issue 14) a camera looking level at the table (its normal is the
// image's up) publishes vertical lines only: the bottle standing upright is found, the one
// leaning 10 deg gets no line at its axis. A channel that names no camera is refused.
TEST(SymmetryHandlers, UprightCheckKeepsOnlyLinesThatCanStandOnTheTable) {
  nudge::symmetry_service::Options options = mono_options();
  options.inputs = {"CAMERA_LEFT"};
  options.params.num_lines = 10;
  options.verify = true;
  options.verify_params.keep = 3;
  nudge::symmetry_service::Options::Upright upright;
  for (nudge::geometry::Camera* camera : {&upright.rig.left, &upright.rig.right}) {
    camera->width = 320;
    camera->height = 240;
    camera->K << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1;
  }
  upright.rig.T = Eigen::Vector3d(-0.1, 0, 0);
  upright.table.normal = Eigen::Vector3d(0, -1, 0);
  upright.table.offset = 0.3;
  upright.max_tilt_deg = 2;
  options.upright = upright;
  InProcess run(options);
  Latest<nudge::symmetry_lines_t> left_lines(run.probe, "SYMMETRY_LEFT");
  auto publish = [&](double theta_deg, int64_t utime) {
    nudge::image_t image = bottle_image(20, theta_deg * kDeg, utime);
    run.bus.publish("CAMERA_LEFT", &image);
    run.service.handle_pending();
    return left_lines.get();
  };
  const nudge::symmetry_lines_t standing = publish(0, 1);
  ASSERT_GE(standing.num_lines, 1);
  EXPECT_NEAR(standing.lines[0].r, 20, 1.0);
  EXPECT_NEAR(standing.lines[0].theta, 0, 1.0 * kDeg);
  const nudge::symmetry_lines_t leaning = publish(10, 2);
  EXPECT_EQ(leaning.utime, 2);
  for (int i = 0; i < leaning.num_lines; ++i) EXPECT_GT(std::fabs(leaning.lines[i].theta - 10 * kDeg), 2 * kDeg);
  EXPECT_EQ(run.service.counters().errors, 0);
  // Without the check the leaning bottle's axis is published first.
  options.upright.reset();
  InProcess unchecked(options);
  Latest<nudge::symmetry_lines_t> unchecked_lines(unchecked.probe, "SYMMETRY_LEFT");
  nudge::image_t image = bottle_image(20, 10 * kDeg, 3);
  unchecked.bus.publish("CAMERA_LEFT", &image);
  unchecked.service.handle_pending();
  ASSERT_GE(unchecked_lines.get().num_lines, 1);
  EXPECT_NEAR(unchecked_lines.get().lines[0].theta, 10 * kDeg, 1.0 * kDeg);
  EXPECT_EQ(nudge::symmetry_service::side_of_channel("CAMERA_RIGHT"), nudge::geometry::Side::Right);
  EXPECT_THROW(nudge::symmetry_service::side_of_channel("CAMERA"), std::invalid_argument);
}

// The arm's base column left out (Options::column_mask_*): a bottle inside the masked region gives
// no line, the same bottle unmasked does; a frame of another size than the mask is an error,
// counted, and the service goes on.
TEST(SymmetryHandlers, TheColumnMaskLeavesTheMaskedRegionOutOfTheVoting) {
  nudge::symmetry_service::Options options = mono_options();
  options.inputs = {"CAMERA_RIGHT"};
  options.column_mask_left = cv::Mat(240, 320, CV_8UC1, cv::Scalar(0));
  options.column_mask_right = cv::Mat(240, 320, CV_8UC1, cv::Scalar(0));
  options.column_mask_right(cv::Rect(140, 0, 80, 240)).setTo(255);  // around the line at r = 20
  InProcess run(options);
  Latest<nudge::symmetry_lines_t> right(run.probe, "SYMMETRY_RIGHT");
  auto lines_at = [&](double r, int64_t utime) {
    nudge::image_t image = bottle_image(r, 0, utime);
    run.bus.publish("CAMERA_RIGHT", &image);
    run.service.handle_pending();
    const nudge::symmetry_lines_t m = right.get();
    int near = 0;
    for (int i = 0; i < m.num_lines; ++i) near += std::fabs(m.lines[i].r - r) < 3 && std::fabs(m.lines[i].theta) < 2 * kDeg;
    return near;
  };
  EXPECT_EQ(lines_at(20, 1), 0) << "the bottle behind the mask";
  EXPECT_EQ(lines_at(-90, 2), 1) << "the same bottle beside it";
  nudge::image_t small = nudge::bus::to_message(cv::Mat(120, 160, CV_8UC3, cv::Scalar(200, 210, 220)),
                                                nudge::image_t::FORMAT_GRAY8, 3, 3, "mono");
  run.bus.publish("CAMERA_RIGHT", &small);
  run.service.handle_pending();
  EXPECT_EQ(run.service.counters().errors, 1);
  EXPECT_NE(run.service.counters().last_error().find("column mask"), std::string::npos) << run.service.counters().last_error();
}

// The table's texture left out (Options::table_texture). Two cameras at one place looking at a
// plane ahead see it alike everywhere, so where both images agree the edges are the "table's":
// a bottle in both images is left out; a bottle only in the right image (the left sees the bare
// background there) keeps its line. An image waits for its partner from the other camera; one
// whose partner is too far in time is dropped; an image of the wrong size is an error, counted.
TEST(SymmetryHandlers, TheTableTextureLeavesWhatBothCamerasSeeAlikeOutOfTheVoting) {
  nudge::symmetry_service::Options options = mono_options();
  options.inputs = {"CAMERA_LEFT", "CAMERA_RIGHT"};
  nudge::geometry::StereoRig rig;
  for (nudge::geometry::Camera* camera : {&rig.left, &rig.right}) {
    camera->width = 320;
    camera->height = 240;
    camera->K << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1;
  }
  nudge::geometry::Plane ahead;  // z = 1 m, facing the cameras
  ahead.normal = Eigen::Vector3d(0, 0, -1);
  ahead.offset = 1.0;
  options.table_texture = nudge::symmetry_service::Options::TableTexture{
      nudge::geometry::plane_warp(rig, nudge::geometry::Side::Left, ahead),
      nudge::geometry::plane_warp(rig, nudge::geometry::Side::Right, ahead), {}, 20000};
  InProcess run(options);
  Latest<nudge::symmetry_lines_t> left(run.probe, "SYMMETRY_LEFT"), right(run.probe, "SYMMETRY_RIGHT");
  const auto bare = nudge::bus::to_message(cv::Mat(240, 320, CV_8UC3, cv::Scalar(200, 210, 220)),
                                           nudge::image_t::FORMAT_GRAY8, 0, 0, "left");
  auto lines_near = [](const nudge::symmetry_lines_t& m, double r) {
    int near = 0;
    for (int i = 0; i < m.num_lines; ++i) near += std::fabs(m.lines[i].r - r) < 3 && std::fabs(m.lines[i].theta) < 2 * kDeg;
    return near;
  };
  int frame = 0;
  auto publish = [&](const char* channel, nudge::image_t image, int64_t utime) {
    image.utime = utime;
    image.frame_id = frame++ / 2;  // one frame number per moment, as a stereo camera sends
    run.bus.publish(channel, &image);
    run.service.handle_pending();
  };

  publish("CAMERA_LEFT", bottle_image(20, 0, 0), 1000);
  EXPECT_FALSE(left.has()) << "the left image waits for the right one";
  publish("CAMERA_RIGHT", bottle_image(20, 0, 0), 1000);
  ASSERT_EQ(left.count(), 1);
  ASSERT_EQ(right.count(), 1);
  EXPECT_EQ(left.get().utime, 1000);
  EXPECT_EQ(lines_near(left.get(), 20), 0) << "both cameras see the bottle alike: the table's";
  EXPECT_EQ(lines_near(right.get(), 20), 0);

  publish("CAMERA_LEFT", bare, 2000);
  publish("CAMERA_RIGHT", bottle_image(20, 0, 0), 2000);
  ASSERT_EQ(right.count(), 2);
  EXPECT_EQ(right.get().utime, 2000);
  EXPECT_EQ(lines_near(right.get(), 20), 1) << "the bottle only the right camera sees";

  publish("CAMERA_LEFT", bare, 3000);
  publish("CAMERA_RIGHT", bottle_image(20, 0, 0), 3000 + 50000);  // 50 ms later: not its partner
  EXPECT_EQ(left.count(), 2) << "the unpaired left image is not published";
  EXPECT_EQ(right.count(), 2) << "the right one waits for its own partner";
  publish("CAMERA_LEFT", bare, 3000 + 50000 + 5000);  // 5 ms off: its partner
  EXPECT_EQ(left.count(), 3);
  EXPECT_EQ(right.count(), 3);
  EXPECT_EQ(right.get().utime, 53000);

  publish("CAMERA_RIGHT", nudge::bus::to_message(cv::Mat(120, 160, CV_8UC3, cv::Scalar(200, 210, 220)),
                                                 nudge::image_t::FORMAT_GRAY8, 0, 0, "right"), 4000);
  EXPECT_EQ(run.service.counters().errors, 1);
  EXPECT_NE(run.service.counters().last_error().find("table texture"), std::string::npos) << run.service.counters().last_error();
}

// Only lines standing within reach (Options::reach): a camera looking level over a table 0.3 m
// below it. The bottle's line stands on the table in front of the camera: kept when the reach
// is around it, dropped when the reach is around a place 20 m away.
TEST(SymmetryHandlers, OnlyLinesStandingWithinReachArePublished) {
  nudge::symmetry_service::Options options = mono_options();
  options.inputs = {"CAMERA_RIGHT"};
  nudge::symmetry_service::Options::Reach reach = level_reach();
  auto lines_with = [&](const Eigen::Vector3d& centre) {
    reach.centre = centre;
    options.reach = reach;
    InProcess run(options);
    Latest<nudge::symmetry_lines_t> right(run.probe, "SYMMETRY_RIGHT");
    nudge::image_t image = bottle_image(20, 0, 1);
    run.bus.publish("CAMERA_RIGHT", &image);
    run.service.handle_pending();
    EXPECT_EQ(run.service.counters().errors, 0);
    return right.get();
  };
  const nudge::symmetry_lines_t near = lines_with(Eigen::Vector3d(0, 0.3, 1.0));
  ASSERT_EQ(near.num_lines, 1) << "--reach-keep 1";
  EXPECT_NEAR(near.lines[0].r, 20, 1.0);
  EXPECT_EQ(lines_with(Eigen::Vector3d(0, 0.3, 20.0)).num_lines, 0);

  // Beside the bottle, above the horizon (out of reach), a striped panel whose peak outvotes the
  // bottle's more than tenfold, as the arm's base column does a cup once the arm has withdrawn.
  // The weak-peak cut (min_peak_ratio 0.1) is made among the lines within reach: the bottle stays.
  reach.centre = Eigen::Vector3d(0, 0.3, 1.0);
  options.reach = reach;
  options.params.num_lines = 60;  // the panel's stripes give dozens of peaks
  InProcess run(options);
  Latest<nudge::symmetry_lines_t> right(run.probe, "SYMMETRY_RIGHT");
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 210, 220));
  syn::draw_shape(img, syn::bottle_profile(64, 20), 60, 0, 0, cv::Scalar(40, 60, 90));
  for (int stripe = 0; stripe < 24; ++stripe)
    if (stripe % 2 == 0) cv::rectangle(img, cv::Rect(10 + 5 * stripe, 0, 5, 115), cv::Scalar(30, 30, 30), cv::FILLED);
  nudge::image_t image = nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, 1, 1, "right");
  run.bus.publish("CAMERA_RIGHT", &image);
  run.service.handle_pending();
  const nudge::symmetry_lines_t lines = right.get();
  ASSERT_GE(lines.num_lines, 1);
  EXPECT_NEAR(lines.lines[0].r, 60, 1.0) << "the bottle, the strongest line within reach";
  // The panel's own peak, as the detector alone finds it: more than ten times the bottle's.
  nudge::symmetry::Params alone = options.params;
  alone.min_peak_ratio = 0;
  const auto all = nudge::symmetry::Detector(alone).detect(img);
  ASSERT_GE(all.lines.size(), 2u);
  EXPECT_NEAR(all.lines[0].r, 10 + 5 * 11.5 - 159.5, 3.0) << "the panel's axis";
  EXPECT_GT(all.lines[0].votes, 10 * lines.lines[0].votes);
}

// The arm's base column rides along without counting among the lines kept within reach
// (Reach::column_px): with one line kept, the strongest line, standing where the column does,
// no longer keeps the next object's line out. A column line ranked after the kept lines is not
// added, and with column_px 0 the column counts (as before).
TEST(SymmetryHandlers, TheArmBaseColumnsLineDoesNotTakeAPlaceAmongTheLinesKept) {
  nudge::symmetry_service::Options options = two_bottle_options();
  nudge::symmetry_service::Options::Reach reach = level_reach();
  const cv::Mat img = two_bottles(0);
  // An upright axis at x = Z r / f projects to the vertical line at r (the camera is level).
  const auto column_at = [](double r) { return Eigen::Vector3d(r / 300.0, 0.3, 1.0); };
  auto published = [&](double column_px, const Eigen::Vector3d& column) {
    reach.column_px = column_px;
    reach.centre = column;
    options.reach = reach;
    std::vector<double> r;
    for (const auto& line : right_lines_of(options, img).lines) r.push_back(line.r);
    return r;
  };
  const std::vector<double> counted = published(0, column_at(60));
  ASSERT_EQ(counted.size(), 1u) << "column_px 0: the column's line counts";
  EXPECT_NEAR(counted[0], 60, 1.0);
  const std::vector<double> uncounted = published(8, column_at(60));
  ASSERT_EQ(uncounted.size(), 2u) << "the column's line and the one line kept";
  EXPECT_NEAR(uncounted[0], 60, 1.0);
  EXPECT_NEAR(uncounted[1], -80, 1.0);
  const std::vector<double> column_second = published(8, column_at(-80));
  ASSERT_EQ(column_second.size(), 1u) << "a column line after the kept lines is not added";
  EXPECT_NEAR(column_second[0], 60, 1.0);
}

// Each place once before any twice (Reach::one_per_place_px): a tall bottle whose label sits 12 px
// off its axis gives two lines (its outline's and its label's) that outvote a short bottle 140 px
// away and fill the two lines kept; with a line within 16 px of a stronger one waiting, the short
// bottle's line takes the second place.
TEST(SymmetryHandlers, OneLinePerPlaceLetsALoneObjectsLineIn) {
  nudge::symmetry_service::Options options = two_bottle_options();
  nudge::symmetry_service::Options::Reach reach = level_reach();
  reach.centre = Eigen::Vector3d(0, 0.3, 1.0);
  reach.keep = 2;
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 210, 220));
  syn::draw_shape(img, syn::bottle_profile(170, 30), 60, 0, 0, cv::Scalar(40, 60, 90));
  cv::rectangle(img, cv::Rect(213, 38, 29, 166), cv::Scalar(140, 150, 160), cv::FILLED);  // a label off its axis
  syn::draw_shape(img, syn::bottle_profile(40, 30), -80, 0, 0, cv::Scalar(40, 60, 90));
  auto published = [&](double one_per_place_px) {
    reach.one_per_place_px = one_per_place_px;
    options.reach = reach;
    std::vector<double> r;
    for (const auto& line : right_lines_of(options, img).lines) r.push_back(line.r);
    return r;
  };
  const std::vector<double> crowded = published(0);
  ASSERT_EQ(crowded.size(), 2u);
  for (double r : crowded) EXPECT_GT(r, 40) << "without it both places go to the pair of bottles";
  const std::vector<double> spread = published(16);
  ASSERT_EQ(spread.size(), 2u);
  EXPECT_EQ(spread[0], crowded[0]) << "the strongest line first, as before";
  EXPECT_NEAR(spread[1], -80, 1.0) << "the lone bottle's line in the second place";
}

// Lines that cannot be an upright object's axis leave before the lines kept within reach are
// chosen (Reach::max_tilt_deg): with one line kept, a leaning bottle (12 deg in a level camera)
// that outvotes an upright one takes the place without the check, and gives it up with it.
TEST(SymmetryHandlers, LeaningLinesDoNotTakeThePlacesOfUprightOnes) {
  nudge::symmetry_service::Options options = two_bottle_options();
  nudge::symmetry_service::Options::Reach reach = level_reach();
  reach.centre = Eigen::Vector3d(0, 0.3, 1.0);
  const cv::Mat img = two_bottles(12 * kDeg, 170);
  auto published = [&](double max_tilt_deg) {
    reach.max_tilt_deg = max_tilt_deg;
    options.reach = reach;
    return right_lines_of(options, img);
  };
  const nudge::symmetry_lines_t unchecked = published(0);
  ASSERT_EQ(unchecked.num_lines, 1);
  EXPECT_NEAR(unchecked.lines[0].theta, 12 * kDeg, 1.5 * kDeg) << "without the check the leaning bottle is kept";
  const nudge::symmetry_lines_t checked = published(5);
  ASSERT_EQ(checked.num_lines, 1);
  EXPECT_NEAR(checked.lines[0].r, -80, 1.0) << "the upright bottle";
  EXPECT_NEAR(checked.lines[0].theta, 0, 1.5 * kDeg);
  const nudge::symmetry_lines_t loose = published(15);
  ASSERT_EQ(loose.num_lines, 1);
  EXPECT_NEAR(loose.lines[0].theta, 12 * kDeg, 1.5 * kDeg) << "a 15 deg check lets a 12 deg lean through";
}

// The objects a survey has explored leave the edges (Options::explored): once a CANDIDATES_REQUEST
// names the strongest bottle's place, the one line kept within reach is the other bottle's; a
// request naming nothing brings the first back, and a place that is not finite is passed over.
TEST(SymmetryHandlers, ExploredObjectsLeaveTheEdgesFromTheSurveyThatNamesThem) {
  nudge::symmetry_service::Options options = two_bottle_options();
  nudge::symmetry_service::Options::Reach reach = level_reach();
  reach.centre = Eigen::Vector3d(0, 0.3, 1.0);
  options.reach = reach;
  nudge::symmetry_service::Options::Explored explored;
  explored.rig = reach.rig;
  explored.table = reach.table;
  explored.arm_base = reach.centre;
  explored.radius = 0.12;  // the bottle is 60 px (0.2 m) wide at 1 m
  explored.height = 0.6;
  options.explored = explored;
  const cv::Mat img = two_bottles(0);

  InProcess run(options);
  Latest<nudge::symmetry_lines_t> right(run.probe, "SYMMETRY_RIGHT");
  nudge::image_t image = nudge::bus::to_message(img, nudge::image_t::FORMAT_GRAY8, 1, 1, "right");
  auto top_line = [&] {
    run.bus.publish("CAMERA_RIGHT", &image);
    run.service.handle_pending();
    EXPECT_EQ(run.service.counters().errors, 0);
    const nudge::symmetry_lines_t lines = right.get();
    EXPECT_EQ(lines.num_lines, 1);
    return lines.num_lines > 0 ? lines.lines[0].r : NAN;
  };
  auto request = [&](const std::vector<Eigen::Vector3d>& places) {
    nudge::candidates_request_t msg{};
    msg.utime = 2;
    msg.num_explored = static_cast<int32_t>(places.size());
    for (const Eigen::Vector3d& p : places) msg.explored.push_back({p.x(), p.y(), p.z()});
    run.bus.publish("CANDIDATES_REQUEST", &msg);
    run.service.handle_pending();
  };
  const nudge::geometry::TableFrame frame(explored.table, explored.arm_base);
  // An upright axis at x = Z r / f projects to the vertical line at r (the camera is level).
  const Eigen::Vector3d strongest = frame.to_table(Eigen::Vector3d(60 / 300.0, 0.3, 1.0));
  EXPECT_NEAR(top_line(), 60, 1.0) << "nothing explored yet";
  request({strongest});
  EXPECT_NEAR(top_line(), -80, 1.0) << "the explored bottle's edges are left out";
  request({});
  EXPECT_NEAR(top_line(), 60, 1.0) << "a survey that names nothing explored";
  request({Eigen::Vector3d(NAN, 0, 0)});
  EXPECT_NEAR(top_line(), 60, 1.0) << "a place that is not finite is passed over";
}
