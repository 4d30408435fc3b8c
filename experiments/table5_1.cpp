// Thesis Table 5.1 on this machine: symmetry tracker computation per 640x480 frame (one camera,
// single thread), and the end-to-end latency from a camera frame published over LCM to its
// TRACK_LEFT message from a separate nudge-tracker process. The latency part runs both processes
// in a private network namespace made for the purpose (needs root, as the integration tests), so
// no traffic leaves it; without one it reports the latency as unavailable and why.
//   nudge-exp-table5_1 [--frames 300]
// Writes docs/results/table5_1.{json,md}.
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgproc.hpp>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/timing.hpp"
#include "nudge/track_t.hpp"
#include "nudge/tracking/tracker.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace syn = nudge::symmetry::synthetic;

namespace {

// A bottle swinging across a cluttered room: 640x480 grey frames at 25 Hz, still for 8 frames.
std::vector<cv::Mat> swinging_bottle(int frames) {
  const cv::Mat room = syn::indoor_scene(11, 640, 480, 2);
  std::vector<cv::Mat> out;
  for (int i = 0; i < frames; ++i) {
    cv::Mat frame = room.clone();
    const double t = std::max(0, i - 8) / 25.0;
    const double r = 120 * std::sin(1.3 * t), theta = 0.15 * std::sin(0.9 * t);
    syn::draw_shape(frame, syn::bottle_profile(220, 38), r, theta, 20, cv::Scalar(40, 40, 180));
    cv::Mat grey;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    out.push_back(grey);
  }
  return out;
}

std::vector<double> tracker_times(const std::vector<cv::Mat>& frames) {
  tracking::SymmetryTracker tracker;
  std::vector<double> ms;
  for (size_t i = 0; i < frames.size(); ++i) {
    Stopwatch watch;
    tracker.feed(frames[i], static_cast<int64_t>(i) * 40000);
    ms.push_back(watch.elapsed_ms());
  }
  return ms;
}

std::string own_directory() {
  char path[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return ".";
  path[n] = 0;
  const std::string exe(path);
  return exe.substr(0, exe.rfind('/'));
}

// Publishes the frames at 25 Hz to a nudge-tracker process and times each TRACK_LEFT's arrival.
// Returns an empty vector and sets *why when there is no private network to do it in.
std::vector<double> lcm_latencies(const std::vector<cv::Mat>& frames, std::string* why) {
  if (geteuid() != 0 || unshare(CLONE_NEWNET) != 0) {
    *why = "needs root to make a private network namespace";
    return {};
  }
  if (std::system("ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo && "
                  "sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216") != 0) {
    *why = "could not set up loopback multicast in the namespace";
    return {};
  }
  const std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216";
  const std::string tracker = own_directory() + "/nudge-tracker";
  const pid_t child = fork();
  if (child == 0) {
    execl(tracker.c_str(), tracker.c_str(), "--lcm-url", url.c_str(), "--inputs", bus::channel::CAMERA_LEFT, nullptr);
    _exit(127);
  }
  lcm::LCM lcm(url);
  std::map<int64_t, int64_t> sent, received;  // frame id -> wall utime
  struct Receiver {
    std::map<int64_t, int64_t>* received;
    void on_track(const lcm::ReceiveBuffer*, const std::string&, const track_t* msg) {
      (*received)[msg->frame_id] = wall_utime();
    }
  } receiver{&received};
  lcm.subscribe(bus::channel::TRACK_LEFT, &Receiver::on_track, &receiver);
  usleep(800000);  // let the tracker subscribe
  int64_t next = wall_utime();
  for (size_t i = 0; i < frames.size(); ++i) {
    const int64_t now = wall_utime();
    const image_t msg = bus::to_message(frames[i], image_t::FORMAT_GRAY8, now, static_cast<int64_t>(i), "left");
    sent[static_cast<int64_t>(i)] = now;
    lcm.publish(bus::channel::CAMERA_LEFT, &msg);
    next += 40000;
    while (wall_utime() < next) lcm.handleTimeout(std::max<int>(1, static_cast<int>((next - wall_utime()) / 1000)));
  }
  const int64_t deadline = wall_utime() + 1000000;
  while (wall_utime() < deadline) lcm.handleTimeout(50);
  kill(child, SIGINT);
  waitpid(child, nullptr, 0);
  std::vector<double> latency;
  for (const auto& [id, t] : received)
    if (sent.count(id)) latency.push_back((t - sent[id]) / 1000.0);
  if (latency.empty()) *why = "no TRACK_LEFT message arrived from " + tracker;
  return latency;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 300;
  Flags flags("nudge-exp-table5_1", "Thesis Table 5.1: tracker time per frame and LCM latency.");
  flags.add_int("frames", &frames, "frames of the test video");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (frames < 20) throw FlagError("--frames must be >= 20");
    nudge::Progress progress("nudge-exp-table5_1", 3);  // the video, the tracker's time, the latency over LCM
    progress.step("drawing " + std::to_string(frames) + " frames");
    const auto video = swinging_bottle(frames);
    progress.step("tracker time per frame");
    const std::vector<double> ms = tracker_times(video);
    const double median_ms = median(ms);
    std::string why;
    progress.step("latency over LCM (" + std::to_string(frames / 25) + " s at 25 Hz)");
    const std::vector<double> latency = lcm_latencies(video, &why);
    progress.clear_status();  // the result files' "wrote" lines follow on stderr
    JsonWriter j;
    j.begin_object();
    j.field("machine", machine_description()).field("date", today()).field("frames", frames);
    j.field("fps_per_camera", 1000.0 / median_ms).field("median_ms_per_frame", median_ms);
    j.field("mean_ms_per_frame", mean(ms));
    if (latency.empty()) j.key("latency_ms_lcm").value(std::nan("")).field("latency_note", why);
    else j.field("latency_ms_lcm", median(latency)).field("latency_frames", static_cast<int>(latency.size()));
    j.field("thesis_fps", 40);
    j.end_object();
    write_result("table5_1.json", j.str() + "\n");
    std::ostringstream md;
    md << "# Table 5.1 — symmetry tracker speed\n\n"
       << "A 640×480 video of a bottle swinging across a cluttered room (`synthetic::indoor_scene`), "
       << frames << " frames at 25 Hz. Tracker computation per frame on one thread (block motion, edges in the "
          "moving region, angle-limited detection, Kalman filter, refined mask); latency = from publishing a "
          "frame on `CAMERA_LEFT` to receiving its `TRACK_LEFT` from a separate `nudge-tracker` process over "
          "LCM UDP multicast (loopback of a private network namespace).\n\nMachine: "
       << machine_description() << ", " << today() << ".\n\n| | this machine | thesis |\n|---|---|---|\n"
       << "| median ms per frame | " << median_ms << " | 25 (40 fps) |\n"
       << "| frames per second per camera | " << 1000.0 / median_ms << " | 40 |\n"
       << "| median latency camera → TRACK over LCM (ms) | "
       << (latency.empty() ? "unavailable: " + why : std::to_string(median(latency))) << " | – |\n";
    write_result("table5_1.md", md.str());
    std::ostringstream summary;
    summary << median_ms << " ms per frame, latency ";
    if (latency.empty()) summary << "unavailable";
    else summary << median(latency) << " ms";
    progress.finish(summary.str());
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-table5_1: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
