// monitor: shows what the pipeline detects. Prints one line per SYMMETRY_* message, optionally
// draws the lines over the matching CAMERA_* frame (paired by utime) into PNG files, and can
// check that every frame got its lines (--expect-frames, for tests and the demo).
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <sys/stat.h>

#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/log.hpp"
#include "nudge/timing.hpp"

using namespace nudge;

namespace {

std::string camera_channel_for(const std::string& symmetry_channel) {
  return "CAMERA" + symmetry_channel.substr(std::string("SYMMETRY").size());
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("monitor", [&] {
    bus::Service service("monitor", "Prints and draws symmetry detections; checks that every frame got lines.");
    std::string channels = "SYMMETRY_LEFT,SYMMETRY_RIGHT", draw_dir;
    int expect_frames = 0;
    double timeout_s = 0;
    auto& f = service.flags();
    f.add_string("channels", &channels, "comma-separated SYMMETRY_* channels");
    f.add_string("draw-dir", &draw_dir, "write frames with their lines here (needs the CAMERA_* images)");
    f.add_int("expect-frames", &expect_frames, "exit 0 once this many frames per channel got lines, else 1");
    f.add_double("timeout", &timeout_s, "give up after this many seconds (0: never)");
    if (!service.parse(argc, argv)) return 0;
    std::vector<std::string> list;
    std::stringstream ss(channels);
    for (std::string c; std::getline(ss, c, ',');)
      if (!c.empty()) list.push_back(c);
    if (list.empty()) throw FlagError("--channels is empty");
    if (!draw_dir.empty()) ::mkdir(draw_dir.c_str(), 0755);
    service.start();

    std::map<std::string, std::map<int64_t, cv::Mat>> frames;  // camera channel -> utime -> image
    std::map<std::string, std::set<int64_t>> seen;
    for (const auto& channel : list) {
      const std::string cam = camera_channel_for(channel);
      if (!draw_dir.empty()) {
        service.subscriptions().subscribe<image_t>(cam, [&, cam](const image_t& msg, const std::string&) {
          auto& store = frames[cam];
          store[msg.utime] = bus::to_mat(msg);
          while (store.size() > 50) store.erase(store.begin());  // keep memory bounded
        });
      }
      service.subscriptions().subscribe<symmetry_lines_t>(channel, [&, cam](const symmetry_lines_t& msg,
                                                                           const std::string& ch) {
        seen[ch].insert(msg.utime);
        std::ostringstream line;
        line << ch << " frame " << msg.frame_id << ": " << msg.num_edges << " edges, "
             << (msg.ms_edges + msg.ms_vote + msg.ms_peaks) << " ms;";
        for (const auto& l : msg.lines) line << " (r " << l.r << ", theta " << l.theta * 180.0 / M_PI << " deg)";
        log::info() << line.str();
        if (draw_dir.empty()) return;
        const auto it = frames[cam].find(msg.utime);
        if (it == frames[cam].end()) return;
        std::vector<symmetry::Line> lines;
        for (const auto& l : msg.lines) lines.push_back(bus::from_message(l));
        char name[64];
        std::snprintf(name, sizeof name, "/%s_%06lld.png", ch.c_str(), static_cast<long long>(msg.frame_id));
        cv::imwrite(draw_dir + name, symmetry::draw_lines(it->second, lines));
      });
    }
    const int64_t deadline = timeout_s > 0 ? wall_utime() + static_cast<int64_t>(timeout_s * 1e6) : 0;
    bool complete = false;
    const int rc = service.run([&]() -> int {
      if (expect_frames > 0) {
        complete = true;
        for (const auto& c : list) complete &= static_cast<int>(seen[c].size()) >= expect_frames;
        if (complete) service.request_stop();
      }
      if (deadline && wall_utime() > deadline) service.request_stop();
      return 20;
    });
    if (expect_frames > 0) {
      for (const auto& c : list) log::info() << c << ": lines for " << seen[c].size() << " frames";
      return complete ? 0 : 1;
    }
    return rc;
  });
}
