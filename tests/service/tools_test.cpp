// The camera service and the nudge-detect tool run as processes: the camera writes straight into
// an LCM log (file provider) so stereo pairing can be checked without a network; nudge-detect is
// run on image files with known axes and on an unreadable one.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <opencv2/imgcodecs.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <regex>
#include <string>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/test/run_service.hpp"

namespace syn = nudge::symmetry::synthetic;
namespace channel = nudge::bus::channel;

namespace {

std::string bin(const std::string& name) { return std::string(NUDGE_BIN_DIR) + "/" + name; }

// Runs a command; its standard output and then its standard error into *out. Returns the exit code.
int run(const std::string& cmd, std::string* out = nullptr) {
  const auto result = nudge::test::run_capturing(cmd);
  if (out) *out = result.out + result.err;
  return result.exit_code;
}

std::string scratch_dir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/" + name;
  ::mkdir(dir.c_str(), 0755);
  return dir;
}

}  // namespace

TEST(CameraService, StereoPairsShareUtimeAndFrameIds) {
  const std::string dir = scratch_dir("camera_service");
  for (int i = 0; i < 4; ++i) {
    cv::imwrite(dir + "/l" + std::to_string(i) + ".png", cv::Mat(24, 32, CV_8UC3, cv::Scalar(i, 0, 0)));
    cv::imwrite(dir + "/r" + std::to_string(i) + ".png", cv::Mat(24, 32, CV_8UC3, cv::Scalar(0, i, 0)));
  }
  const std::string log_path = dir + "/camera.lcmlog";
  std::remove(log_path.c_str());
  const std::string cmd = bin("nudge-camera") + " --left 'images:" + dir + "/l*.png' --right 'images:" + dir +
                          "/r*.png' --rate 0 --format bgr --lcm-url 'file://" + log_path + "?mode=w'";
  ASSERT_EQ(run(cmd), 0) << cmd;
  std::map<int64_t, std::map<std::string, nudge::image_t>> by_utime;
  const auto events = nudge::test::read_log(log_path);
  for (const std::string channel : {"CAMERA_LEFT", "CAMERA_RIGHT"})
    for (const auto& img : nudge::test::messages_on<nudge::image_t>(events, channel)) by_utime[img.utime][channel] = img;
  ASSERT_EQ(by_utime.size(), 4u) << "four captures";
  int64_t expected_id = 0;
  for (const auto& [utime, pair] : by_utime) {
    ASSERT_EQ(pair.size(), 2u) << "left and right share utime " << utime;
    EXPECT_EQ(pair.at(channel::CAMERA_LEFT).frame_id, expected_id);
    EXPECT_EQ(pair.at(channel::CAMERA_RIGHT).frame_id, expected_id);
    EXPECT_EQ(nudge::bus::to_mat(pair.at(channel::CAMERA_LEFT)).at<cv::Vec3b>(0, 0)[0], expected_id);
    EXPECT_EQ(nudge::bus::to_mat(pair.at(channel::CAMERA_RIGHT)).at<cv::Vec3b>(0, 0)[1], expected_id);
    ++expected_id;
  }
}

TEST(CameraService, BadSourcesAreRefused) {
  std::string out;
  EXPECT_NE(run(bin("nudge-camera") + " --source 'images:/nonexistent/*.png'", &out), 0);
  EXPECT_NE(out.find("matches no files"), std::string::npos) << out;
  EXPECT_EQ(run(bin("nudge-camera") + " --left images:/a", &out), 2);
}

// nudge-camera has its simulator backend only in builds with nudge_sim (MuJoCo and OSMesa);
// tests/CMakeLists.txt tells this test which build it is in.
TEST(CameraService, SourceSimIsRefusedClearlyWhereTheBuildHasNoSimulator) {
  std::string help, out;
  EXPECT_EQ(run(bin("nudge-camera") + " --help", &help), 0);
  const int exit_code = run(bin("nudge-camera") + " --source sim --lcm-in memq://", &out);
  EXPECT_EQ(exit_code, 2) << out;
#ifdef NUDGE_TEST_CAMERA_WITHOUT_SIM
  EXPECT_NE(help.find("not in this build"), std::string::npos) << help;
  EXPECT_NE(out.find("--source sim: this nudge-camera was built without the simulator"), std::string::npos) << out;
#else
  EXPECT_NE(help.find("--source sim --scene FILE renders every SIM_STATE"), std::string::npos) << help;
  EXPECT_NE(out.find("--source sim needs --scene FILE"), std::string::npos) << out;
#endif
}

TEST(DetectTool, FindsKnownAxesAndReportsUnreadableFiles) {
  const std::string dir = scratch_dir("detect_tool");
  struct Case {
    double r, theta_deg;
  };
  const std::vector<Case> cases = {{30.0, 8.0}, {-45.5, -12.5}};
  std::string args;
  for (size_t i = 0; i < cases.size(); ++i) {
    cv::Mat img(300, 400, CV_8UC3, cv::Scalar(210, 220, 230));
    syn::draw_shape(img, syn::bottle_profile(200, 36), cases[i].r, cases[i].theta_deg * M_PI / 180, 0,
                    cv::Scalar(50, 40, 30));
    const std::string path = dir + "/shape" + std::to_string(i) + ".png";
    cv::imwrite(path, img);
    args += " " + path;
    if (i == 0) args += " " + dir + "/missing.png";
  }
  std::string out;
  const int rc = run(bin("nudge-detect") + " --lines 1 --theta-min -45 --theta-max 45 --draw " + dir +
                         "/drawn.png" + args,
                     &out);
  EXPECT_EQ(rc, 1) << "a missing file makes the exit code non-zero";
  const std::regex line_re(R"re(\{"image":"([^"]+)".*?"lines":\[\{"r":([-0-9.e]+),"theta_deg":([-0-9.e]+))re");
  std::vector<std::pair<double, double>> found;
  for (std::sregex_iterator it(out.begin(), out.end(), line_re), end; it != end; ++it) {
    found.emplace_back(std::stod((*it)[2]), std::stod((*it)[3]));
  }
  ASSERT_EQ(found.size(), cases.size()) << "the other images still ran:\n" << out;
  for (size_t i = 0; i < cases.size(); ++i) {
    EXPECT_NEAR(found[i].first, cases[i].r, 1.0);
    EXPECT_NEAR(found[i].second, cases[i].theta_deg, 1.0);
  }
  EXPECT_TRUE(cv::imread(dir + "/drawn_1.png").data != nullptr) << "--draw numbers files for several images";
}

// Issue 12: a truncated JPEG gave exit 0 and lines from the top half of the image; a 389 KB PNG
// declaring 20000x20000 was decoded in full (1.2 GB) before anything refused it.
TEST(DetectTool, TruncatedAndHugeImagesAreErrorsNamingTheFile) {
  const std::string dir = scratch_dir("detect_tool_bad");
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(210, 220, 230));
  syn::draw_shape(img, syn::bottle_profile(200, 36), 10, 0, 0, cv::Scalar(50, 40, 30));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", img, jpeg));
  jpeg.resize(jpeg.size() / 2);
  const std::string truncated = dir + "/truncated.jpg";
  std::FILE* f = std::fopen(truncated.c_str(), "wb");
  ASSERT_TRUE(f);
  std::fwrite(jpeg.data(), 1, jpeg.size(), f);
  std::fclose(f);
  std::string out;
  EXPECT_EQ(run(bin("nudge-detect") + " --lines 1 " + truncated, &out), 1);
  EXPECT_NE(out.find(truncated + ": cannot read the image (JPEG data of " + std::to_string(jpeg.size()) +
                     " bytes is truncated"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("\"lines\""), std::string::npos) << "no lines from half an image:\n" << out;

  std::vector<uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", img, png));
  for (size_t at : {16, 20}) {  // IHDR's width and height: 20000 = 0x4E20
    png[at] = 0;
    png[at + 1] = 0;
    png[at + 2] = 0x4E;
    png[at + 3] = 0x20;
  }
  const std::string huge = dir + "/huge.png";
  f = std::fopen(huge.c_str(), "wb");
  ASSERT_TRUE(f);
  std::fwrite(png.data(), 1, png.size(), f);
  std::fclose(f);
  EXPECT_EQ(run(bin("nudge-detect") + " --lines 1 " + huge, &out), 1);
  EXPECT_NE(out.find(huge + ": cannot read the image (PNG header declares 20000x20000"), std::string::npos) << out;
}
