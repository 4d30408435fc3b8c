// nudge-viewer's page in headless Chromium, on a short log played by nudge-replay: the page's
// replay controls pause and step the player; once it has played to the end, the page shows the
// supervisor's last state, the symmetry lines and tracked box drawn over both cameras, and a
// health table in which a service that stopped sending heartbeats is dead (red). A screenshot of
// the page is saved for a person to look at (its path is printed). Runs in a private network
// namespace (needs root, like the other integration tests); skipped when Chromium is absent.
#include <gtest/gtest.h>
#include <httplib.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

#include "nudge/arm_command_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/process_status_t.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/private_network.hpp"
#include "nudge/test/process.hpp"
#include "nudge/track_t.hpp"

namespace channel = nudge::bus::channel;
using nlohmann::json;
using nudge::test::Process;

namespace {

const std::string kBin = NUDGE_BIN_DIR;
const std::string kUrl = "udpm://239.255.76.67:7667?ttl=0";
const std::string kChromium = "/usr/bin/chromium";
constexpr int64_t kT0 = 1'700'000'000'000'000;  // the log's clock
constexpr int64_t kSecond = 1'000'000;
constexpr int kFrames = 40;                      // 10 Hz for 4 s

nudge::symmetry_line_t vertical_line(float x, float height, float votes) {
  nudge::symmetry_line_t l{};
  l.votes = votes;
  l.x1 = l.x2 = x;
  l.y1 = 0;
  l.y2 = height - 1;
  l.seg_x1 = l.seg_x2 = x;
  l.seg_y1 = height * 0.3f;
  l.seg_y2 = height * 0.7f;
  return l;
}

nudge::heartbeat_t heartbeat(const std::string& service, int64_t utime, int64_t n) {
  nudge::heartbeat_t hb{};
  hb.utime = utime;
  hb.service = service;
  hb.pid = 100 + static_cast<int>(service.size());
  hb.state = nudge::heartbeat_t::STATE_RUNNING;
  hb.messages_in = hb.messages_out = 10 * n;
  hb.status = "ok";
  return hb;
}

nudge::supervisor_state_t supervisor(int64_t utime, int8_t state, const std::string& name, int attempt,
                                     const std::string& reason) {
  nudge::supervisor_state_t s{};
  s.utime = utime;
  s.run_id = "viewer_test";
  s.state = state;
  s.state_name = name;
  s.attempt = attempt;
  s.candidate_index = attempt > 0 ? 0 : -1;
  s.target[0] = 0.3;
  s.reason = reason;
  return s;
}

// A 4 s run, as the services would have logged it: a stereo pair at 10 Hz with two symmetry lines
// each, the right tracker following a box, candidates, a nudge, a segmentation, the supervisor's
// transitions, heartbeats from camera and symmetry throughout and from the tracker only in the
// first second.
// The events, gathered out of order and written in time order (as a logger would have).
class RunLog {
 public:
  template <typename Msg>
  void write(int64_t utime, const std::string& channel, const Msg& msg) {
    events_.push_back({utime, channel, nudge::test::encode(msg)});
  }
  void save(const std::string& path) {
    std::stable_sort(events_.begin(), events_.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
    nudge::test::write_log(path, events_);
  }

 private:
  std::vector<nudge::test::Event> events_;
};

void write_run_log(const std::string& path) {
  RunLog log;
  const int w = 320, h = 240;
  for (int i = 0; i < kFrames; ++i) {
    const int64_t t = kT0 + i * kSecond / 10;
    if (i % 10 == 0) {
      log.write(t, channel::HEARTBEAT, heartbeat("camera", t, i));
      log.write(t, channel::HEARTBEAT, heartbeat("symmetry", t, i));
      if (i <= 10) log.write(t, channel::HEARTBEAT, heartbeat("tracker", t, i));
    }
    for (const std::string side : {"left", "right"}) {
      cv::Mat image(h, w, CV_8UC3, cv::Scalar(60, 90, 60));
      const int cx = 160 + (side == "left" ? 10 : -10) + i;
      cv::ellipse(image, {cx, 120}, {30, 60}, 0, 0, 360, cv::Scalar(200, 200, 230), cv::FILLED);
      const std::string cam = side == "left" ? channel::CAMERA_LEFT : channel::CAMERA_RIGHT;
      log.write(t, cam, nudge::bus::to_message(image, nudge::image_t::FORMAT_MJPEG, t, i, side));
      nudge::symmetry_lines_t lines{};
      lines.utime = t;
      lines.frame_id = i;
      lines.camera = side;
      lines.width = w;
      lines.height = h;
      lines.lines = {vertical_line(cx, h, 90), vertical_line(60, h, 30)};
      lines.num_lines = 2;
      log.write(t + 1000, channel::derived(cam, channel::SYMMETRY), lines);
      nudge::track_t track{};
      track.utime = t;
      track.frame_id = i;
      track.camera = side;
      track.status = nudge::track_t::STATUS_TRACKING;
      track.line = vertical_line(cx, h, 90);
      const float box[4][2] = {{cx - 32.f, 58}, {cx + 32.f, 58}, {cx + 32.f, 182}, {cx - 32.f, 182}};
      std::copy(&box[0][0], &box[0][0] + 8, &track.box[0][0]);
      log.write(t + 2000, channel::derived(cam, channel::TRACK), track);
    }
  }
  using S = nudge::supervisor_state_t;
  log.write(kT0 + 50000, channel::SUPERVISOR_STATE, supervisor(kT0, S::STATE_FIND_CANDIDATES, "FIND_CANDIDATES", 0, "survey"));
  nudge::candidates_t candidates{};
  candidates.utime = kT0 + 500000;
  candidates.num_candidates = 2;
  candidates.position = {{0.30, 0.00, 0.0}, {0.25, 0.15, 0.0}};
  candidates.cluster_size = {8, 5};
  log.write(kT0 + 500000, channel::CANDIDATES, candidates);
  log.write(kT0 + 600000, channel::SUPERVISOR_STATE, supervisor(kT0 + 600000, S::STATE_NUDGE, "NUDGE", 1, "nudging candidate 0"));
  nudge::arm_command_t nudge{};
  nudge.utime = kT0 + 600000;
  nudge.command = nudge::arm_command_t::COMMAND_NUDGE;
  nudge.target.position[0] = 0.30;
  nudge.direction[1] = 1;
  log.write(kT0 + 600000, channel::ARM_COMMAND, nudge);
  log.write(kT0 + 2500000, channel::SUPERVISOR_STATE, supervisor(kT0 + 2500000, S::STATE_SEGMENT, "SEGMENT", 1, "motion beyond the line"));
  nudge::segmentation_t seg{};
  seg.utime = kT0 + 2600000;
  seg.run_id = "viewer_test";
  seg.attempt = 1;
  cv::Mat mask(h, w, CV_8UC1, cv::Scalar(0));
  cv::ellipse(mask, {180, 120}, {30, 60}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  seg.mask = nudge::bus::to_message(mask, nudge::image_t::FORMAT_PNG, seg.utime, 0, "right");
  seg.mask_pixels = cv::countNonZero(mask);
  log.write(kT0 + 2600000, channel::SEGMENTATION, seg);
  nudge::supervisor_state_t done = supervisor(kT0 + 3800000, S::STATE_DONE, "DONE", 1, "nothing left to nudge");
  done.segmented = 1;  // the attempt's segmentation above
  log.write(kT0 + 3800000, channel::SUPERVISOR_STATE, done);
  // nudge-launch's last word: symmetry running, the tracker (silent since 1 s) waiting to restart.
  nudge::process_status_t processes{};
  processes.utime = kT0 + 3000000;
  processes.config = "launch.json";
  processes.num_processes = 2;
  processes.processes.resize(2);
  processes.processes[0].name = "symmetry";
  processes.processes[0].pid = 1234;
  processes.processes[0].state = nudge::process_info_t::STATE_RUNNING;
  processes.processes[0].uptime_s = 3;
  processes.processes[0].last_exit_code = -1;
  processes.processes[1].name = "tracker";
  processes.processes[1].state = nudge::process_info_t::STATE_BACKOFF;
  processes.processes[1].restarts = 1;
  processes.processes[1].last_exit_code = 139;
  processes.processes[1].restart_in_s = 2;
  log.write(kT0 + 3000000, channel::PROCESS_STATUS, processes);
  log.save(path);
}

json get_state(httplib::Client& http) {
  const auto res = http.Get("/api/state");
  if (!res || res->status != 200) return nullptr;
  return json::parse(res->body);
}

// Polls the viewer's state until `done` holds or `seconds` pass; the last state.
template <typename Done>
json wait_state(httplib::Client& http, Done done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  json state;
  do {
    state = get_state(http);
    if (!state.is_null() && done(state)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  } while (std::chrono::steady_clock::now() < end);
  return state;
}

int64_t frame_seq(const json& state, const std::string& camera) {
  if (!state.contains("cameras") || !state["cameras"].contains(camera)) return 0;
  return state["cameras"][camera]["seq"].get<int64_t>();
}

// What headless Chromium renders at `url`, as HTML, after the page ran for a few seconds.
std::string chromium_dom(const std::string& url, const std::string& dir, const std::string& screenshot = "") {
  const std::string out = dir + "/viewer_dom.html";
  std::ostringstream cmd;
  // ?snapshot: the page polls frames without long requests, so that Chromium's virtual time (the
  // page's timers) runs out of its budget; `timeout` guards against a browser that hangs.
  cmd << "timeout 60 " << kChromium << " --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="
      << dir << "/chromium_profile --virtual-time-budget=3000 --window-size=1400,1300 ";
  if (screenshot.empty()) cmd << "--dump-dom '" << url << "?snapshot' > " << out;
  else cmd << "--screenshot=" << screenshot << " '" << url << "?snapshot' > /dev/null";
  cmd << " 2> " << dir << "/chromium.log";
  if (std::system(cmd.str().c_str()) != 0) return "";
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The first line of the answer to a POST sent as `curl -X POST URL` sends it: no body and no
// Content-Length header; "" when none comes within 3 s.
std::string post_without_length(int port, const std::string& target) {
  std::string answer;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval timeout{3, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
    const std::string request = "POST " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
    if (write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size())) {
      char buffer[256];
      const ssize_t n = read(fd, buffer, sizeof buffer);
      if (n > 0) answer.assign(buffer, static_cast<size_t>(n));
    }
  }
  close(fd);
  return answer.substr(0, answer.find("\r\n"));
}

int count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

}  // namespace

TEST(ViewerPage, ShowsAReplayedRunAndPausesAndStepsIt) {
  if (access(kChromium.c_str(), X_OK) != 0) GTEST_SKIP() << "chromium is not installed (Debian package chromium)";
  NUDGE_TEST_ENTER_PRIVATE_NETWORK();
  const std::string dir = testing::TempDir() + "viewer_page_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::string log = dir + "/run.lcmlog";
  write_run_log(log);

  const int port = 18088;
  Process viewer({kBin + "/nudge-viewer", "--lcm-url", kUrl, "--port", std::to_string(port)}, dir + "/viewer.log");
  ASSERT_TRUE(viewer.started());
  httplib::Client http("127.0.0.1", port);
  http.set_read_timeout(3, 0);
  ASSERT_FALSE(wait_state(http, [](const json&) { return true; }, 10).is_null()) << "the viewer did not serve";

  Process replay({kBin + "/nudge-replay", "--lcm-url", kUrl, "--paused", log}, dir + "/replay.log");
  ASSERT_TRUE(replay.started());
  json state = wait_state(http, [](const json& s) { return !s["replay"].is_null(); }, 10);
  ASSERT_FALSE(state["replay"].is_null()) << "no REPLAY_STATUS reached the viewer";
  EXPECT_EQ(state["replay"]["state"], "paused");
  EXPECT_EQ(frame_seq(state, "left"), 0);

  // A step plays up to the next left frame, and no further: the replay stays paused.
  ASSERT_EQ(http.Post("/api/replay?command=step")->status, 200);
  state = wait_state(http, [](const json& s) { return frame_seq(s, "left") >= 1; }, 5);
  EXPECT_EQ(frame_seq(state, "left"), 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  state = get_state(http);
  EXPECT_EQ(frame_seq(state, "left"), 1) << "the paused replay went on after a step";
  EXPECT_EQ(state["replay"]["state"], "paused");
  ASSERT_EQ(http.Post("/api/replay?command=step")->status, 200);
  state = wait_state(http, [](const json& s) { return frame_seq(s, "left") >= 2; }, 5);
  EXPECT_EQ(frame_seq(state, "left"), 2);
  EXPECT_EQ(http.Post("/api/replay?command=jump")->status, 400) << "an unknown command is refused";
  EXPECT_EQ(post_without_length(port, "/api/replay?command=pause"), "HTTP/1.1 200 OK") << "curl -X POST URL";

  // Play at double speed to the end (4 s of log).
  ASSERT_EQ(http.Post("/api/replay?command=speed&speed=2")->status, 200);
  ASSERT_EQ(http.Post("/api/replay?command=play")->status, 200);
  EXPECT_EQ(replay.wait_exit(15), 0) << "the replay did not play to its end";
  state = wait_state(http, [](const json& s) { return frame_seq(s, "right") >= kFrames; }, 3);
  EXPECT_EQ(frame_seq(state, "left"), kFrames);
  EXPECT_EQ(frame_seq(state, "right"), kFrames);
  EXPECT_NEAR(state["cameras"]["left"]["fps"].get<double>(), 10.0, 0.5) << "the camera's rate, from its stamps";
  EXPECT_EQ(state["supervisor"]["current"]["state"], "DONE");
  EXPECT_EQ(state["supervisor"]["timeline"].size(), 4u);
  EXPECT_EQ(state["segmentations"].size(), 1u);
  EXPECT_EQ(http.Get("/api/mask/0")->status, 200);

  // What the page shows, read from the DOM Chromium rendered.
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";
  const std::string dom = chromium_dom(url, dir);
  ASSERT_FALSE(dom.empty()) << "chromium failed; see " << dir << "/chromium.log";
  EXPECT_NE(dom.find("<div id=\"state\">DONE</div>"), std::string::npos) << dom;
  EXPECT_EQ(count(dom, "class=\"sym-line"), 4) << "two symmetry lines over each camera";
  EXPECT_EQ(count(dom, "class=\"track-box\""), 2) << "a tracked box over each camera";
  EXPECT_EQ(count(dom, "class=\"candidate\""), 2);
  EXPECT_EQ(count(dom, "class=\"push\""), 1);
  EXPECT_EQ(count(dom, "<tr class=\"alive\" data-service=\"(camera|symmetry)\">"), 2) << dom;
  EXPECT_EQ(count(dom, "<tr class=\"dead\" data-service=\"tracker\">"), 1) << "silent since 1 s of a 3.9 s log";
  EXPECT_EQ(count(dom, "class=\"mask\""), 1);
  EXPECT_NE(dom.find("replay: finished"), std::string::npos);
  // nudge-launch's status over LCM, as the viewer shows it.
  EXPECT_EQ(count(dom, "<tr class=\"alive\" data-process=\"symmetry\">"), 1) << dom;
  EXPECT_EQ(count(dom, "<tr class=\"dead\" data-process=\"tracker\"><td>tracker</td><td>restarting in 2.0 s</td>"), 1);
  EXPECT_NE(dom.find("segmented 1"), std::string::npos) << "the supervisor's counts under its state";
  // The viewer's own heartbeat is live, judged on the wall clock (not at the log's position).
  EXPECT_EQ(count(dom, "<tr class=\"alive\" data-service=\"viewer/viewer \\(live\\)\">"), 1) << dom;

  const std::string screenshot = dir + "/viewer_replay.png";
  chromium_dom(url, dir, screenshot);
  EXPECT_TRUE(std::filesystem::exists(screenshot) && std::filesystem::file_size(screenshot) > 10000);
  std::cout << "screenshot of the page: " << screenshot << "\n";
}
