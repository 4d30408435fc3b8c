// monitor: shows what the pipeline detects. Prints one line per SYMMETRY_* message, optionally
// draws the lines over the matching CAMERA_* frame (paired by utime) into PNG files, and can
// check that every frame got its lines (--expect-frames, for tests and the demo). In simulation
// (--truth) it compares the lines with the true axes in SIM_STATE and prints a summary at exit.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <sys/stat.h>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/log.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/timing.hpp"

using namespace nudge;

namespace {

constexpr double kDeg = M_PI / 180.0;

// How well one object's true axis was found in one camera: the detected line nearest to it
// (|dR| in px + |dtheta| in degrees) in every frame that had a state.
struct TruthStats {
  int frames = 0, found = 0;        // found: nearest line within the tolerance
  double sum_r = 0, sum_theta = 0;  // over the found frames, px and rad
};

// The true (R, theta) of an object in the camera of a SYMMETRY_LEFT / _RIGHT channel; false for
// other channels and for axes that do not project (NaN).
bool true_line(const object_state_t& o, const std::string& channel, double* r, double* theta) {
  if (channel == bus::channel::SYMMETRY_LEFT) {
    *r = o.r_left;
    *theta = o.theta_left;
  } else if (channel == bus::channel::SYMMETRY_RIGHT) {
    *r = o.r_right;
    *theta = o.theta_right;
  } else {
    return false;
  }
  return std::isfinite(*r) && std::isfinite(*theta);
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("monitor", [&] {
    bus::Service service("monitor", "Prints and draws symmetry detections; checks that every frame got lines.");
    std::string channels = std::string(bus::channel::SYMMETRY_LEFT) + "," + bus::channel::SYMMETRY_RIGHT, draw_dir;
    int expect_frames = 0, allow_missing = 0;
    double timeout_s = 0;
    auto& f = service.flags();
    f.add_string("channels", &channels, "comma-separated SYMMETRY_* channels");
    f.add_string("draw-dir", &draw_dir, "write frames with their lines here (needs the CAMERA_* images)");
    f.add_int("expect-frames", &expect_frames, "exit 0 once this many frames per channel got lines, else 1");
    f.add_int("allow-missing", &allow_missing,
              "with --expect-frames: this many frames per channel may be lost in transport (UDP under load) "
              "and still pass; each is named by its frame id");
    f.add_double("timeout", &timeout_s, "give up after this many seconds (0: never)");
    bool truth = false;
    std::vector<double> tolerance = {3.0, 2.0};
    f.add_bool("truth", &truth, "simulation: compare lines with SIM_STATE's true axes, draw those dashed, summarise");
    f.add_doubles("truth-tolerance", &tolerance, 2, "a true axis counts as found within R px and theta deg");
    if (!service.parse(argc, argv)) return 0;
    if (!(tolerance[0] > 0 && tolerance[1] > 0)) throw FlagError("--truth-tolerance must be > 0");
    if (allow_missing < 0 || (expect_frames > 0 && allow_missing >= expect_frames))
      throw FlagError("--allow-missing must be >= 0 and below --expect-frames");
    const std::vector<std::string> list = split_list(channels);
    if (list.empty()) throw FlagError("--channels is empty");
    if (!draw_dir.empty()) ::mkdir(draw_dir.c_str(), 0755);
    service.start();
    service.watch_heartbeats();  // every service: a killed one is named within 3 s
    // Every service's state and what it reports as they change ("symmetry DEGRADED: CAMERA_LEFT
    // silent for 3.1 s"; numbers ignored, so a counting status is not a change a second): a
    // service that degrades and recovers is seen here, not only in its own log.
    std::map<std::string, std::string> reported;
    service.subscriptions().subscribe<heartbeat_t>(bus::channel::HEARTBEAT, [&](const heartbeat_t& hb, const std::string&) {
      const std::string source = hb.instance.empty() || hb.instance == hb.service ? hb.service : hb.service + "/" + hb.instance;
      std::string key = std::to_string(hb.state) + " ";
      for (char c : hb.status)
        if (!std::isdigit(static_cast<unsigned char>(c))) key += c;
      if (reported[source] == key) return;
      reported[source] = key;
      const char* names[] = {"STARTING", "RUNNING", "DEGRADED", "STOPPING"};  // heartbeat_t::STATE_*
      const std::string state = hb.state >= 0 && hb.state < 4 ? names[hb.state] : "state " + std::to_string(hb.state);
      log::info() << "heartbeat: " << source << " " << state << ": " << hb.status;
    });

    std::map<std::string, std::map<int64_t, cv::Mat>> frames;  // camera channel -> utime -> image
    std::map<std::string, std::set<int64_t>> frame_ids;  // channel -> frame ids with lines
    std::map<int64_t, sim_state_t> states;                            // utime -> state (recent ones)
    std::map<std::string, std::map<std::string, TruthStats>> stats;  // channel -> object -> stats
    if (truth) {
      service.subscriptions().subscribe<sim_state_t>(bus::channel::SIM_STATE, [&](const sim_state_t& msg, const std::string&) {
        states[msg.utime] = msg;
        while (states.size() > 200) states.erase(states.begin());  // keep memory bounded
      });
    }
    for (const auto& channel : list) {
      // the images the lines were found in, only needed to draw them
      const std::string cam = draw_dir.empty() ? "" : bus::channel::camera_of(channel, bus::channel::SYMMETRY);
      if (!draw_dir.empty()) {
        service.subscriptions().subscribe<image_t>(cam, [&, cam](const image_t& msg, const std::string&) {
          auto& store = frames[cam];
          store[msg.utime] = bus::to_mat(msg);
          while (store.size() > 50) store.erase(store.begin());  // keep memory bounded
        });
      }
      service.subscriptions().subscribe<symmetry_lines_t>(channel, [&, cam](const symmetry_lines_t& msg,
                                                                           const std::string& ch) {
        frame_ids[ch].insert(msg.frame_id);
        std::ostringstream line;
        line << ch << " frame " << msg.frame_id << ": " << msg.num_edges << " edges, "
             << (msg.ms_edges + msg.ms_vote + msg.ms_peaks) << " ms;";
        for (const auto& l : msg.lines) line << " (r " << l.r << ", theta " << l.theta * 180.0 / M_PI << " deg)";
        log::info() << line.str();
        const auto state = truth ? states.find(msg.utime) : states.end();
        if (state != states.end()) {
          for (const auto& o : state->second.objects) {
            double r = 0, theta = 0;
            if (!true_line(o, ch, &r, &theta)) continue;
            TruthStats& st = stats[ch][o.name];
            ++st.frames;
            double best = INFINITY, best_r = 0, best_theta = 0;
            for (const auto& l : msg.lines) {
              const symmetry::LineDifference d = symmetry::line_difference(l.r, l.theta, r, theta);
              const double dr = std::abs(d.r), dtheta = std::abs(d.theta);
              if (dr + dtheta / kDeg < best) {
                best = dr + dtheta / kDeg;
                best_r = dr;
                best_theta = dtheta;
              }
            }
            if (best_r <= tolerance[0] && best_theta <= tolerance[1] * kDeg) {
              ++st.found;
              st.sum_r += best_r;
              st.sum_theta += best_theta;
            }
          }
        }
        if (draw_dir.empty()) return;
        const auto it = frames[cam].find(msg.utime);
        if (it == frames[cam].end()) return;
        std::vector<symmetry::Line> lines;
        for (const auto& l : msg.lines) lines.push_back(bus::from_message(l));
        cv::Mat drawn = symmetry::draw_lines(it->second, lines);
        if (state != states.end()) {  // the true axes, dashed white (the detections use colours)
          for (const auto& o : state->second.objects) {
            double r = 0, theta = 0;
            if (!true_line(o, ch, &r, &theta)) continue;
            cv::Point2d a, b;
            symmetry::border_endpoints(r, theta, drawn.cols, drawn.rows, &a, &b);
            const double length = cv::norm(b - a);
            for (double s = 0; s + 6 < length; s += 12)
              cv::line(drawn, a + (b - a) * (s / length), a + (b - a) * ((s + 6) / length), cv::Scalar(255, 255, 255), 1,
                       cv::LINE_AA);
          }
        }
        char name[64];
        std::snprintf(name, sizeof name, "/%s_%06lld.png", ch.c_str(), static_cast<long long>(msg.frame_id));
        cv::imwrite(draw_dir + name, drawn);
      });
    }
    const int64_t deadline = timeout_s > 0 ? wall_utime() + static_cast<int64_t>(timeout_s * 1e6) : 0;
    // Done when every channel has lines for every frame, or (with --allow-missing) has the last
    // frame (id expect_frames - 1) and at most allow_missing gaps before it: nothing more will come.
    const auto channel_done = [&](const std::string& c) {
      const int n = static_cast<int>(frame_ids[c].size());
      if (n >= expect_frames) return true;
      const bool has_last = !frame_ids[c].empty() && *frame_ids[c].rbegin() >= expect_frames - 1;
      return has_last && n >= expect_frames - allow_missing;
    };
    bool complete = false;
    const int rc = service.run([&]() -> int {
      if (expect_frames > 0) {
        complete = true;
        for (const auto& c : list) complete &= channel_done(c);
        if (complete) service.request_stop();
      }
      if (deadline && wall_utime() > deadline) service.request_stop();
      return 20;
    });
    for (const auto& [channel, objects] : stats) {
      for (const auto& [object, st] : objects) {
        std::ostringstream line;
        line << "truth " << channel << " " << object << ": found in " << st.found << "/" << st.frames
             << " frames (within " << tolerance[0] << " px, " << tolerance[1] << " deg)";
        if (st.found > 0)
          line << ", mean error " << st.sum_r / st.found << " px, " << st.sum_theta / st.found / kDeg << " deg";
        log::info() << line.str();
      }
    }
    if (expect_frames > 0) {
      bool enough = true;
      for (const auto& c : list) {
        log::info() << c << ": lines for " << frame_ids[c].size() << " frames";
        std::ostringstream missing;
        for (int64_t id = 0; id < expect_frames; ++id)
          if (!frame_ids[c].count(id)) missing << " " << id;
        if (!missing.str().empty()) log::warn() << c << ": no lines for frame(s)" << missing.str();
        enough &= static_cast<int>(frame_ids[c].size()) >= expect_frames - allow_missing;
      }
      return complete || enough ? 0 : 1;
    }
    return rc;
  });
}
