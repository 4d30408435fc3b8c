#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/decode.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/bus/subscribe.hpp"
#include "nudge/arm_command_t.hpp"
#include "nudge/axes_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/learn_view_t.hpp"
#include "nudge/recognition_t.hpp"
#include "nudge/recognize_request_t.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/track_t.hpp"

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


// ---- malformed bytes on the bus (issue 12) ---------------------------------------------------

namespace {

using Bytes = std::vector<uint8_t>;

template <typename Msg>
Bytes encode(const Msg& msg) {
  Bytes bytes(msg.getEncodedSize());
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

void put_int32(Bytes* bytes, size_t offset, int32_t value) {
  for (int i = 0; i < 4; ++i) (*bytes)[offset + i] = static_cast<uint8_t>(static_cast<uint32_t>(value) >> (24 - 8 * i));
}

// A small grey image_t from camera "left" (string length 5 with its NUL) and the offsets of the
// lengths it declares: fingerprint 8, utime 8, frame_id 8, then the camera's length.
constexpr size_t kCameraLengthOffset = 24;
constexpr size_t kSizeOffset = kCameraLengthOffset + 4 + 5 + 4 + 4 + 4 + 1;

Bytes small_image_bytes() {
  const image_t msg = bus::to_message(cv::Mat(4, 6, CV_8UC1, cv::Scalar(9)), image_t::FORMAT_GRAY8, 1, 2, "left");
  return encode(msg);
}

Bytes image_bytes_with(size_t offset, int32_t value) {
  Bytes bytes = small_image_bytes();
  put_int32(&bytes, offset, value);
  return bytes;
}

}  // namespace

TEST(Decode, WellFormedImageDecodes) {
  const Bytes bytes = small_image_bytes();
  image_t msg;
  EXPECT_EQ(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &msg), "");
  EXPECT_EQ(msg.camera, "left");
  EXPECT_EQ(msg.size, 24);
}

TEST(Decode, ImageLengthsBeyondTheBytesAreRefusedBeforeDecoding) {
  for (int32_t size : {-1, 25, 2000000000}) {
    const Bytes bytes = image_bytes_with(kSizeOffset, size);
    const std::string problem = bus::check_encoded_image(bytes.data(), static_cast<int>(bytes.size()));
    EXPECT_NE(problem.find("size declares " + std::to_string(size)), std::string::npos) << problem;
    image_t msg;
    EXPECT_EQ(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &msg), problem);
    EXPECT_TRUE(msg.data.empty()) << "nothing allocated for size " << size;
  }
  for (int32_t camera_length : {0, -7, 1000}) {
    const Bytes bytes = image_bytes_with(kCameraLengthOffset, camera_length);
    const std::string problem = bus::check_encoded_image(bytes.data(), static_cast<int>(bytes.size()));
    EXPECT_NE(problem.find("camera declares " + std::to_string(camera_length)), std::string::npos) << problem;
  }
  Bytes truncated = small_image_bytes();
  truncated.resize(kSizeOffset + 2);
  EXPECT_NE(bus::check_encoded_image(truncated.data(), static_cast<int>(truncated.size())).find("too short"),
            std::string::npos);
}

TEST(Decode, ExceptionsInsideDecodeBecomeErrors) {
  // A heartbeat whose first string declares length 0: LCM 1.3.1's decode() throws (it assigns
  // length - 1 characters); no pre-decode check covers heartbeat_t, so the catch must.
  heartbeat_t hb{};
  hb.service = "symmetry";
  Bytes bytes = encode(hb);
  put_int32(&bytes, 8 + 8, 0);  // fingerprint, utime, then the service string's length
  heartbeat_t msg;
  const std::string problem = bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &msg);
  EXPECT_NE(problem.find("do not decode as heartbeat_t"), std::string::npos) << problem;
}

TEST(Subscriptions, MalformedMessagesAreCountedAndSkippedNamingTheChannel) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  bus::Counters counters;
  bus::Subscriptions subscriptions(lcm, counters);
  int images = 0, heartbeats = 0;
  subscriptions.subscribe<image_t>("CAMERA_TEST", [&](const image_t&, const std::string&) { ++images; });
  subscriptions.subscribe<heartbeat_t>("HEARTBEAT_TEST", [&](const heartbeat_t&, const std::string&) { ++heartbeats; });

  Bytes bad_heartbeat = encode(heartbeat_t{});
  put_int32(&bad_heartbeat, 16, -1);
  const std::vector<std::pair<std::string, Bytes>> sent = {
      {"CAMERA_TEST", small_image_bytes()},
      {"CAMERA_TEST", image_bytes_with(kCameraLengthOffset, 0)},
      {"CAMERA_TEST", image_bytes_with(kSizeOffset, -1)},
      {"CAMERA_TEST", image_bytes_with(kSizeOffset, 2000000000)},
      {"CAMERA_TEST", Bytes{1, 2, 3}},
      {"HEARTBEAT_TEST", bad_heartbeat},
      {"CAMERA_TEST", small_image_bytes()},
  };
  testing::internal::CaptureStderr();
  for (const auto& [channel, bytes] : sent) {
    lcm.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    ASSERT_GT(lcm.handleTimeout(1000), 0) << "memq delivers at once";
  }
  const std::string log = testing::internal::GetCapturedStderr();

  EXPECT_EQ(images, 2);
  EXPECT_EQ(heartbeats, 0);
  EXPECT_EQ(counters.messages_in, 7);
  EXPECT_EQ(counters.errors, 5);
  EXPECT_NE(log.find("skipped a malformed message on CAMERA_TEST: image_t of"), std::string::npos) << log;
  EXPECT_NE(log.find("skipped a malformed message on HEARTBEAT_TEST"), std::string::npos) << log;
}

// The tap sees every message a typed handler is given, just before it (malformed ones too, which
// the handler never sees), in order, and nothing on channels without a typed subscription: what a
// recorder needs to log exactly what the handlers saw (the supervisor's run log).
TEST(Subscriptions, TheTapSeesWhatTheTypedHandlersAreGivenInOrder) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  bus::Counters counters;
  bus::Subscriptions subscriptions(lcm, counters);
  std::vector<std::string> seen;
  subscriptions.subscribe<image_t>("CAMERA_TEST", [&](const image_t&, const std::string& c) { seen.push_back("handled " + c); });
  subscriptions.subscribe<heartbeat_t>("HEARTBEAT_TEST", [&](const heartbeat_t&, const std::string& c) { seen.push_back("handled " + c); });
  subscriptions.set_tap([&](const lcm::ReceiveBuffer* rbuf, const std::string& c) {
    seen.push_back("tapped " + c + " " + std::to_string(rbuf->data_size));
  });
  EXPECT_TRUE(subscriptions.has_typed("CAMERA_TEST"));
  EXPECT_FALSE(subscriptions.has_typed("CAMERA"));
  EXPECT_FALSE(subscriptions.has_typed("OTHER"));

  const Bytes image = small_image_bytes(), heartbeat = encode(heartbeat_t{}), junk{1, 2, 3};
  const std::vector<std::pair<std::string, Bytes>> sent = {
      {"CAMERA_TEST", image}, {"OTHER", junk}, {"HEARTBEAT_TEST", heartbeat}, {"CAMERA_TEST", junk}};
  testing::internal::CaptureStderr();
  for (const auto& [channel, bytes] : sent) {
    lcm.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    lcm.handleTimeout(100);
  }
  testing::internal::GetCapturedStderr();
  const std::vector<std::string> expected = {"tapped CAMERA_TEST " + std::to_string(image.size()), "handled CAMERA_TEST",
                                             "tapped HEARTBEAT_TEST " + std::to_string(heartbeat.size()),
                                             "handled HEARTBEAT_TEST", "tapped CAMERA_TEST 3"};
  EXPECT_EQ(seen, expected);
}

// Which subscriptions are streams (their queue is --queue, docs/reliability.md "Soak"): frames and
// what is computed from them, and the simulated world's state; never commands, requests, states
// or heartbeats. (LCM 1.3.1's memq:// ignores queue capacities, so what udpm:// drops is measured
// by the soak, not here.)
TEST(Subscriptions, StreamsAreFramesAndWhatComesOfThemNotCommandsOrHeartbeats) {
  EXPECT_TRUE(bus::IsStream<image_t>::value);
  EXPECT_TRUE(bus::IsStream<symmetry_lines_t>::value);
  EXPECT_TRUE(bus::IsStream<track_t>::value);
  EXPECT_TRUE(bus::IsStream<contours_t>::value);
  EXPECT_TRUE(bus::IsStream<sim_state_t>::value);
  EXPECT_FALSE(bus::IsStream<heartbeat_t>::value);
  EXPECT_FALSE(bus::IsStream<arm_command_t>::value);
  EXPECT_FALSE(bus::IsStream<candidates_t>::value);
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  bus::Counters counters;
  bus::Subscriptions subscriptions(lcm, counters);
  subscriptions.subscribe<image_t>("CAMERA_TEST", [](const image_t&, const std::string&) {});
  EXPECT_NO_THROW(subscriptions.set_stream_queue_capacity(3));
  EXPECT_THROW(subscriptions.set_stream_queue_capacity(-1), std::invalid_argument);
}

// ---- channel names ----------------------------------------------------------------------------

TEST(Channels, CameraChannelsNameTheirResults) {
  namespace channel = bus::channel;
  EXPECT_EQ(channel::derived(channel::CAMERA_LEFT, channel::SYMMETRY), channel::SYMMETRY_LEFT);
  EXPECT_EQ(channel::derived(channel::CAMERA_RIGHT, channel::SYMMETRY), channel::SYMMETRY_RIGHT);
  EXPECT_EQ(channel::derived(channel::CAMERA_LEFT, channel::CONTOURS), channel::CONTOURS_LEFT);
  EXPECT_EQ(channel::derived(channel::CAMERA_RIGHT, channel::TRACK), channel::TRACK_RIGHT);
  EXPECT_EQ(channel::derived(channel::CAMERA, channel::SYMMETRY), channel::SYMMETRY);
  EXPECT_EQ(channel::derived("LEFT_EYE", channel::TRACK), "TRACK_LEFT_EYE");
}

TEST(Channels, ResultsNameTheirCamera) {
  namespace channel = bus::channel;
  EXPECT_EQ(channel::camera_of(channel::SYMMETRY_LEFT, channel::SYMMETRY), channel::CAMERA_LEFT);
  EXPECT_EQ(channel::camera_of(channel::SYMMETRY, channel::SYMMETRY), channel::CAMERA);
  EXPECT_EQ(channel::camera_of(channel::TRACK_RIGHT, channel::TRACK), channel::CAMERA_RIGHT);
  for (const char* camera : {channel::CAMERA_LEFT, channel::CAMERA_RIGHT, channel::CAMERA})
    EXPECT_EQ(channel::camera_of(channel::derived(camera, channel::CONTOURS), channel::CONTOURS), camera);
  try {
    channel::camera_of("AXES", channel::SYMMETRY);
    ADD_FAILURE() << "AXES is not a symmetry channel";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("AXES"), std::string::npos) << e.what();
  }
}

// ---- pose_t <-> Eigen ------------------------------------------------------------------------

TEST(PoseConvert, IsometryRoundTrips) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.25, -0.1, 0.42);
  const pose_t msg = bus::to_message(pose);
  EXPECT_DOUBLE_EQ(msg.position[2], 0.42);
  Eigen::Isometry3d back;
  ASSERT_TRUE(bus::from_message(msg, &back));
  EXPECT_LT((back.matrix() - pose.matrix()).norm(), 1e-12);
  EXPECT_FALSE(bus::is_unset(msg));
}

TEST(PoseConvert, PositionAndQuaternionRoundTripAsSent) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const pose_t msg = bus::to_message(Eigen::Vector3d(1, 2, 3), q);
  EXPECT_DOUBLE_EQ(msg.orientation[0], q.w());  // (w, x, y, z)
  EXPECT_DOUBLE_EQ(msg.orientation[3], q.z());
  EXPECT_EQ(bus::position_of(msg), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(bus::orientation_of(msg).coeffs(), q.coeffs());
}

TEST(PoseConvert, BadPosesAreRefused) {
  Eigen::Isometry3d pose;
  pose_t unset{};
  EXPECT_TRUE(bus::is_unset(unset));
  EXPECT_FALSE(bus::from_message(unset, &pose)) << "a zero quaternion is no rotation";
  pose_t not_unit = bus::to_message(Eigen::Isometry3d::Identity());
  not_unit.orientation[0] = 2;
  EXPECT_FALSE(bus::from_message(not_unit, &pose));
  pose_t nan = bus::to_message(Eigen::Isometry3d::Identity());
  nan.position[1] = std::nan("");
  EXPECT_FALSE(bus::from_message(nan, &pose));
  pose_t nearly_unit = bus::to_message(Eigen::Isometry3d::Identity());
  nearly_unit.orientation[0] = 1.0005;  // within 1e-3: normalised
  ASSERT_TRUE(bus::from_message(nearly_unit, &pose));
  EXPECT_LT((pose.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

// ---- compressed images: the header is read before the pixels (issue 12) -----------------------

TEST(Image, HugeDeclaredPngIsRefusedBeforeDecoding) {
  // A real PNG whose IHDR is rewritten to 20000x20000: decoding it would allocate 1.2 GB.
  image_t msg = bus::to_message(test_image(), image_t::FORMAT_PNG, 0, 9, "left");
  for (size_t at : {16, 20}) {
    msg.data[at] = 0;
    msg.data[at + 1] = 0;
    msg.data[at + 2] = 0x4E;  // 20000 = 0x4E20
    msg.data[at + 3] = 0x20;
  }
  msg.width = msg.height = 20000;
  try {
    bus::to_mat(msg);
    FAIL() << "a 20000x20000 PNG was decoded";
  } catch (const bus::ImageError& e) {
    EXPECT_NE(std::string(e.what()).find("'left' frame 9: PNG data refused: PNG header declares 20000x20000"),
              std::string::npos)
        << e.what();
  }
}

TEST(Image, TruncatedJpegIsRefusedNotDecodedInPart) {
  image_t msg = bus::to_message(test_image(), image_t::FORMAT_MJPEG, 0, 2, "right");
  msg.data.resize(msg.data.size() * 2 / 3);  // libjpeg would return the top of the image with a warning
  try {
    bus::to_mat(msg);
    FAIL() << "a truncated JPEG was decoded";
  } catch (const bus::ImageError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
}

// ---- declared array lengths (issue 12, found by fuzz_messages) -------------------------------

namespace {
// Where a big-endian int32 `count` is followed by `next` (the first element's first bytes).
size_t find_count(const Bytes& bytes, int32_t count, const Bytes& next) {
  Bytes pattern(4);
  put_int32(&pattern, 0, count);
  pattern.insert(pattern.end(), next.begin(), next.end());
  const auto it = std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end());
  return it == bytes.end() ? std::string::npos : static_cast<size_t>(it - bytes.begin());
}

// Valid messages with 0 and 3 elements (and strings of several lengths) pass the pre-decode
// check and decode: the layouts in decode.cpp match the types.
template <typename Msg, typename Fill>
void expect_valid_pass(Fill fill) {
  for (int n : {0, 3}) {
    for (const std::string text : {"", "left", "a longer camera name"}) {
      Msg msg{};
      fill(&msg, n, text);
      const Bytes bytes = encode(msg);
      Msg back;
      EXPECT_EQ(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &back), "")
          << Msg::getTypeName() << " with " << n << " elements, string '" << text << "'";
    }
  }
}
}  // namespace

TEST(Decode, ValidMessagesWithArraysPassTheLengthChecks) {
  expect_valid_pass<arm_command_t>([](arm_command_t* m, int n, const std::string&) {
    m->num_joints = n;
    m->joints.assign(n, 0.5);
  });
  expect_valid_pass<candidates_t>([](candidates_t* m, int n, const std::string&) {
    m->num_candidates = n;
    m->position.assign(n, std::vector<double>(3, 0.1));
    m->cluster_size.assign(n, 4);
  });
  expect_valid_pass<axes_t>([](axes_t* m, int n, const std::string&) {
    m->num_axes = n;
    m->axes.resize(n);
  });
  expect_valid_pass<symmetry_lines_t>([](symmetry_lines_t* m, int n, const std::string& text) {
    m->camera = text;
    m->num_lines = n;
    m->lines.resize(n);
  });
  expect_valid_pass<track_t>([](track_t* m, int n, const std::string& text) {
    m->camera = text;
    m->reason = text + text;
    m->num_blocks = n;
    m->motion_mask.assign(n, 1);
  });
  expect_valid_pass<sim_state_t>([](sim_state_t* m, int n, const std::string& text) {
    m->num_objects = n;
    m->objects.resize(n);
    for (auto& o : m->objects) o.name = text;
  });
  expect_valid_pass<recognition_t>([](recognition_t* m, int n, const std::string& text) {
    m->label = text;
    m->reason = text + "!";
    m->num_objects = n;
    m->names.assign(n, text);
    m->matches.assign(n, 7);
    m->match_picture.camera = text;
  });
  expect_valid_pass<contours_t>([](contours_t* m, int n, const std::string& text) {
    m->camera = text;
    m->num_contours = n;
    m->contours.resize(n);
  });
  expect_valid_pass<learn_view_t>([](learn_view_t* m, int n, const std::string& text) {
    m->run_id = text;
    m->object_key = text + "x";
    m->image.camera = text;
    m->image.size = n;
    m->image.data.assign(n, 9);
  });
  expect_valid_pass<recognize_request_t>([](recognize_request_t* m, int n, const std::string& text) {
    m->image.camera = text;
    m->image.size = n;
    m->image.data.assign(n, 9);
  });
}

// The learner's inputs carry an image_t inside: its declared size is checked before LCM's
// decode() allocates it (a 2 GB claim in a hundred bytes).
TEST(Decode, NestedImageSizesBeyondTheBytesAreRefusedBeforeAllocating) {
  learn_view_t view{};
  view.run_id = "run";
  view.object_key = "attempt_01";
  view.image.camera = "right";
  view.image.size = 3;
  view.image.data = {0xAB, 0xAB, 0xAB};
  Bytes bytes = encode(view);
  size_t at = find_count(bytes, 3, {0xAB});
  ASSERT_NE(at, std::string::npos);
  put_int32(&bytes, at, 2000000000);
  learn_view_t back;
  EXPECT_NE(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &back).find("image.size declares 2000000000"),
            std::string::npos);
  recognize_request_t request{};
  request.image.camera = "right";
  request.image.size = 3;
  request.image.data = {0xAB, 0xAB, 0xAB};
  bytes = encode(request);
  at = find_count(bytes, 3, {0xAB});
  ASSERT_NE(at, std::string::npos);
  put_int32(&bytes, at, -1);
  recognize_request_t request_back;
  EXPECT_NE(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &request_back).find("image.size declares -1"),
            std::string::npos);
}

TEST(Decode, ArrayCountsBeyondTheBytesAreRefusedBeforeAllocating) {
  arm_command_t command{};
  command.num_joints = 3;
  command.joints = {1.5, 1.5, 1.5};
  Bytes bytes = encode(command);
  const size_t at = find_count(bytes, 3, {0x3F, 0xF8});  // 1.5 = 0x3FF8...
  ASSERT_NE(at, std::string::npos);
  put_int32(&bytes, at, 2000000000);  // 16 GB of doubles in 157 bytes
  arm_command_t back;
  const std::string problem = bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &back);
  EXPECT_NE(problem.find("arm_command_t of " + std::to_string(bytes.size()) + " bytes: num_joints declares 2000000000"),
            std::string::npos)
      << problem;
  put_int32(&bytes, at, -1);
  EXPECT_NE(bus::decode_message(bytes.data(), static_cast<int>(bytes.size()), &back).find("declares -1"),
            std::string::npos);

  symmetry_lines_t lines{};
  lines.camera = "right";
  lines.num_lines = 2;
  lines.lines.resize(2);
  lines.lines[0].r = 1.5f;  // 0x3FC00000
  Bytes line_bytes = encode(lines);
  const size_t lines_at = find_count(line_bytes, 2, {0x3F, 0xC0, 0x00, 0x00});
  ASSERT_NE(lines_at, std::string::npos);
  put_int32(&line_bytes, lines_at, 3);  // one more line than the bytes hold
  symmetry_lines_t lines_back;
  EXPECT_NE(bus::decode_message(line_bytes.data(), static_cast<int>(line_bytes.size()), &lines_back)
                .find("num_lines declares 3"),
            std::string::npos);
}
