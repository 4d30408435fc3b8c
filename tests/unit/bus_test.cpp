#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "nudge/bus/image.hpp"

using namespace nudge;

namespace {
cv::Mat test_image() {
  cv::Mat img(37, 53, CV_8UC3);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) img.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 4, y * 6, (x + y) % 256);
  return img;
}
}  // namespace

TEST(Image, RawFormatsRoundTripExactly) {
  const cv::Mat bgr = test_image();
  for (int8_t format : {image_t::FORMAT_BGR8, image_t::FORMAT_RGB8}) {
    const image_t msg = bus::to_message(bgr, format, 123, 4, "left");
    EXPECT_EQ(msg.utime, 123);
    EXPECT_EQ(msg.frame_id, 4);
    EXPECT_EQ(msg.size, static_cast<int32_t>(msg.data.size()));
    const cv::Mat back = bus::to_mat(msg);
    EXPECT_EQ(cv::norm(back, bgr, cv::NORM_INF), 0) << bus::format_name(format);
  }
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(bus::to_mat(bus::to_message(bgr, image_t::FORMAT_GRAY8, 0, 0, "x")), grey, cv::NORM_INF), 0);
}

TEST(Image, CompressedFormatsDecode) {
  const cv::Mat bgr = test_image();
  EXPECT_EQ(cv::norm(bus::to_mat(bus::to_message(bgr, image_t::FORMAT_PNG, 0, 0, "x")), bgr, cv::NORM_INF), 0);
  const cv::Mat jpeg = bus::to_mat(bus::to_message(bgr, image_t::FORMAT_MJPEG, 0, 0, "x", 95));
  ASSERT_EQ(jpeg.size(), bgr.size());
  EXPECT_LT(cv::norm(jpeg, bgr, cv::NORM_L1) / bgr.total() / 3, 8.0);
}

TEST(Image, StrideIsHonoured) {
  image_t msg;
  msg.width = 3;
  msg.height = 2;
  msg.row_stride = 5;  // 2 bytes of padding per row
  msg.pixel_format = image_t::FORMAT_GRAY8;
  msg.data = {1, 2, 3, 0, 0, 4, 5, 6};
  msg.size = static_cast<int32_t>(msg.data.size());
  const cv::Mat m = bus::to_mat(msg);
  EXPECT_EQ(m.at<uint8_t>(1, 0), 4);
  EXPECT_EQ(m.at<uint8_t>(1, 2), 6);
}

TEST(Image, MalformedImagesAreClearErrorsNamingTheImage) {
  image_t msg = bus::to_message(test_image(), image_t::FORMAT_BGR8, 0, 17, "right");
  auto error_of = [](const image_t& m) {
    try {
      bus::to_mat(m);
    } catch (const bus::ImageError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  image_t truncated = msg;
  truncated.data.resize(truncated.data.size() - 10);
  EXPECT_NE(error_of(truncated).find("right"), std::string::npos);
  EXPECT_NE(error_of(truncated).find("bytes"), std::string::npos);
  image_t unknown = msg;
  unknown.pixel_format = 99;
  EXPECT_NE(error_of(unknown).find("unknown pixel format"), std::string::npos);
  image_t bad_size = msg;
  bad_size.width = -4;
  EXPECT_FALSE(error_of(bad_size).empty());
  image_t bad_stride = msg;
  bad_stride.row_stride = 10;
  EXPECT_NE(error_of(bad_stride).find("row_stride"), std::string::npos);
  image_t garbage = bus::to_message(test_image(), image_t::FORMAT_PNG, 0, 3, "left");
  garbage.data.assign(100, 7);
  EXPECT_NE(error_of(garbage).find("does not decode"), std::string::npos);
  EXPECT_THROW(bus::format_from_name("tiff"), bus::ImageError);
}

