// The simulated camera's sensor: Gaussian pixel noise and the motion-blur average of renders.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <random>
#include <stdexcept>
#include <vector>

#include "nudge/sim/sensor.hpp"

using nudge::sim::add_sensor_noise;
using nudge::sim::average_frames;

namespace {

// Mean and standard deviation over every channel of every pixel.
std::pair<double, double> mean_and_std(const cv::Mat& image) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(image.reshape(1), mean, stddev);
  return {mean[0], stddev[0]};
}

}  // namespace

TEST(SimSensor, NoiseOnAFloatImageHasZeroMeanAndTheGivenSigma) {
  cv::Mat image = cv::Mat::zeros(200, 300, CV_32FC3);
  std::mt19937_64 rng(7);
  add_sensor_noise(image, 3.0, rng);
  const auto [mean, stddev] = mean_and_std(image);
  // 180000 samples: the mean's standard error is 3 / sqrt(180000) = 0.007.
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_NEAR(stddev, 3.0, 0.05);
}

TEST(SimSensor, NoiseOnAnEightBitImageKeepsItsMeanAndRounds) {
  cv::Mat image(200, 300, CV_8UC3, cv::Scalar::all(128));
  std::mt19937_64 rng(11);
  add_sensor_noise(image, 5.0, rng);
  ASSERT_EQ(image.type(), CV_8UC3);
  const auto [mean, stddev] = mean_and_std(image);
  EXPECT_NEAR(mean, 128.0, 0.1);
  // Rounding to whole grey levels adds a uniform error of variance 1/12.
  EXPECT_NEAR(stddev, std::sqrt(25.0 + 1.0 / 12), 0.08);
}

TEST(SimSensor, NoiseSaturatesAtWhite) {
  cv::Mat image(100, 100, CV_8UC1, cv::Scalar(255));
  std::mt19937_64 rng(3);
  add_sensor_noise(image, 4.0, rng);
  double lowest = 0, highest = 0;
  cv::minMaxLoc(image, &lowest, &highest);
  EXPECT_EQ(highest, 255);
  EXPECT_LT(lowest, 250);
  // Half the draws push above white and are clipped there.
  EXPECT_NEAR(cv::countNonZero(image == 255) / 10000.0, 0.5, 0.05);
}

TEST(SimSensor, NoiseIsDeterministicForASeedAndFreshForAnother) {
  const cv::Mat clean(60, 80, CV_8UC3, cv::Scalar(90, 120, 150));
  auto noisy = [&](uint64_t seed) {
    cv::Mat image = clean.clone();
    std::mt19937_64 rng(seed);
    add_sensor_noise(image, 2.0, rng);
    return image;
  };
  EXPECT_EQ(cv::norm(noisy(42), noisy(42), cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(noisy(42), noisy(43), cv::NORM_L1), 0);
  EXPECT_GT(cv::norm(noisy(42), clean, cv::NORM_L1), 0);
}

TEST(SimSensor, ZeroSigmaLeavesTheImageAndTheGeneratorAlone) {
  const cv::Mat clean(20, 30, CV_8UC3, cv::Scalar(10, 20, 30));
  cv::Mat image = clean.clone();
  std::mt19937_64 rng(5), untouched(5);
  add_sensor_noise(image, 0.0, rng);
  EXPECT_EQ(cv::norm(image, clean, cv::NORM_INF), 0);
  EXPECT_EQ(rng(), untouched());
}

TEST(SimSensor, NoiseRefusesDepthsOtherThanEightBitAndFloat) {
  cv::Mat image(10, 10, CV_16UC1, cv::Scalar(1000));
  std::mt19937_64 rng(1);
  EXPECT_THROW(add_sensor_noise(image, 1.0, rng), std::invalid_argument);
}

TEST(SimSensor, BlurOfIdenticalFramesIsTheFrame) {
  cv::Mat frame(48, 64, CV_8UC3);
  cv::randu(frame, 0, 256);
  const cv::Mat mean = average_frames(std::vector<cv::Mat>(6, frame));
  ASSERT_EQ(mean.type(), CV_32FC3);
  cv::Mat back;
  mean.convertTo(back, CV_8UC3);
  EXPECT_EQ(cv::norm(back, frame, cv::NORM_INF), 0);
}

TEST(SimSensor, BlurIsThePerPixelMean) {
  const cv::Mat dark(4, 5, CV_8UC1, cv::Scalar(10)), bright(4, 5, CV_8UC1, cv::Scalar(40));
  const cv::Mat mean = average_frames({dark, bright, bright, bright});
  ASSERT_EQ(mean.type(), CV_32FC1);
  double lowest = 0, highest = 0;
  cv::minMaxLoc(mean, &lowest, &highest);
  EXPECT_FLOAT_EQ(lowest, 32.5);
  EXPECT_FLOAT_EQ(highest, 32.5);
}

TEST(SimSensor, BlurRefusesNoFramesAndFramesThatDoNotMatch) {
  EXPECT_THROW(average_frames({}), std::invalid_argument);
  const cv::Mat a(4, 5, CV_8UC3), b(4, 6, CV_8UC3), c(4, 5, CV_8UC1);
  try {
    average_frames({a, a, b});
    FAIL() << "frames of different sizes averaged";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frame 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(average_frames({a, c}), std::invalid_argument);
}
