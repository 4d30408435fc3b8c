// nudge-segment as a process: a synthetic bottle with a known outline is segmented; the printed
// contour must follow the outline, the picture must be written, and an unreadable image is reported
// while the others still run.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <string>

#include "nudge/symmetry/synthetic.hpp"
#include "nudge/test/run_service.hpp"

namespace syn = nudge::symmetry::synthetic;

namespace {

// Runs a command; its standard output into *out. Returns the exit code.
int run(const std::string& cmd, std::string* out) {
  const auto result = nudge::test::run_capturing(cmd);
  *out = result.out;
  return result.exit_code;
}

// The [[x, y], ...] array after "key": in a JSON text.
std::vector<cv::Point2d> points_after(const std::string& json, const std::string& key) {
  std::vector<cv::Point2d> points;
  const auto start = json.find("\"" + key + "\":[");
  if (start == std::string::npos) return points;
  const auto end = json.find("]]", start);
  const std::string array = json.substr(start, end - start + 2);
  const std::regex pair(R"(\[(-?[0-9.]+),(-?[0-9.]+)\])");
  for (auto it = std::sregex_iterator(array.begin(), array.end(), pair); it != std::sregex_iterator(); ++it)
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  return points;
}

}  // namespace

TEST(SegmentTool, BottleContourFollowsTheOutline) {
  const std::string dir = testing::TempDir() + "/nudge_segment_tool_" + std::to_string(::getpid());
  ::mkdir(dir.c_str(), 0755);
  constexpr double kR = -40, kTheta = 8 * M_PI / 180;
  cv::Mat image(480, 640, CV_8UC3, cv::Scalar(200, 205, 210));
  const auto profile = syn::bottle_profile(300, 55);
  syn::draw_shape(image, profile, kR, kTheta, 0, cv::Scalar(40, 60, 90));
  ASSERT_TRUE(cv::imwrite(dir + "/bottle.png", image));
  std::ofstream(dir + "/broken.png") << "not an image";
  const std::string picture = dir + "/contours.png";
  std::remove((dir + "/contours_1.png").c_str());

  std::string out;
  const std::string cmd = std::string(NUDGE_BIN_DIR) + "/nudge-segment " + dir + "/bottle.png " + dir +
                          "/broken.png --lines 1 --dmin 10 --dmax 0 --theta-min -30 --theta-max 30 --canny 30 90" +
                          " --blur 1 --draw " + picture;
  EXPECT_EQ(run(cmd, &out), 1) << "the unreadable image makes the exit code 1";
  ASSERT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << "one JSON line, for the readable image: " << out;

  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"("line":\{"r":(-?[0-9.e+-]+),"theta_deg":(-?[0-9.e+-]+))")));
  EXPECT_NEAR(std::stod(m[1]), kR, 1.5);
  EXPECT_NEAR(std::stod(m[2]), 8.0, 1.0);

  const auto outline = syn::outline(profile, kR, kTheta, 0, 640, 480);
  std::vector<cv::Point2f> polygon(outline.begin(), outline.end());
  for (const std::string side : {"left", "right"}) {
    const auto points = points_after(out, side);
    ASSERT_GT(points.size(), 200u) << side;
    int near = 0;
    for (const auto& p : points)
      near += std::fabs(cv::pointPolygonTest(polygon, cv::Point2f(p.x, p.y), true)) <= 2.0;
    EXPECT_GE(near, 0.9 * points.size()) << side << ": contour points within 2 px of the outline";
  }
  const cv::Mat drawn = cv::imread(dir + "/contours_1.png");
  ASSERT_FALSE(drawn.empty()) << "--draw numbers the pictures when several images are given";
  EXPECT_EQ(drawn.size(), image.size());
}

TEST(SegmentTool, BadFlagsAreUsageErrors) {
  std::string out;
  const std::string bin = std::string(NUDGE_BIN_DIR) + "/nudge-segment";
  for (const std::string args : {" x.png --max-mid 0", " x.png --max-width 1", " x.png --canny 90", " --lines 2"}) {
    EXPECT_EQ(run(bin + args, &out), 2) << args;
  }
}
