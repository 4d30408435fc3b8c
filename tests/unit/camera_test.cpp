#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <sys/stat.h>

#include <fstream>

#include "nudge/camera/image_file.hpp"
#include "nudge/camera/source.hpp"

using namespace nudge::camera;

TEST(CameraSource, ImagesInNameOrderSkippingUnreadableFilesAndRewinding) {
  const std::string dir = testing::TempDir() + "/camera_source_test";
  ::mkdir(dir.c_str(), 0755);
  for (int i : {2, 0, 1}) {
    cv::imwrite(dir + "/f" + std::to_string(i) + ".png", cv::Mat(4, 6, CV_8UC3, cv::Scalar(i * 10, 0, 0)));
  }
  { std::ofstream bad(dir + "/f1b.png"); bad << "not an image"; }
  auto source = open_source("images:" + dir + "/f*.png");
  cv::Mat frame;
  std::vector<int> seen;
  while (source->read(&frame)) seen.push_back(frame.at<cv::Vec3b>(0, 0)[0]);
  EXPECT_EQ(seen, (std::vector<int>{0, 10, 20}));
  ASSERT_TRUE(source->rewind());
  ASSERT_TRUE(source->read(&frame));
  EXPECT_EQ(frame.at<cv::Vec3b>(0, 0)[0], 0);
}

TEST(CameraSource, BadSpecsAreClearErrors) {
  auto error_of = [](const std::string& spec) {
    try {
      open_source(spec);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("images:/nonexistent/*.png").find("matches no files"), std::string::npos);
  EXPECT_NE(error_of("video:/nonexistent.mp4").find("cannot be opened"), std::string::npos);
  EXPECT_NE(error_of("webcam").find("unknown camera source"), std::string::npos);
  EXPECT_NE(error_of("device:abc").find("device index"), std::string::npos);
}

TEST(ImageFile, UnreadableFilesAreNamedWithWhy) {
  auto error_of = [](const std::string& path) {
    try {
      read_image_file(path, cv::IMREAD_COLOR);
    } catch (const ImageFileError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string dir = testing::TempDir() + "/image_file_test.png";  // a directory named like an image
  ::mkdir(dir.c_str(), 0755);
  EXPECT_NE(error_of(dir).find("a directory, not an image file"), std::string::npos) << error_of(dir);
  EXPECT_NE(error_of(dir + "/missing.png").find("missing or unreadable"), std::string::npos);
  const std::string empty = dir + "/empty.png";
  { std::ofstream touch(empty); }
  EXPECT_NE(error_of(empty).find("the file is empty"), std::string::npos);
  const std::string text = dir + "/text.jpg";
  { std::ofstream out(text); out << "hello"; }
  EXPECT_NE(error_of(text).find("not an image OpenCV decodes"), std::string::npos);
}
