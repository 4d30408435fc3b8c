// tracker: one symmetry tracker (thesis ch. 5) per camera channel. Every image on an input channel
// yields a track_t on the matching output channel (CAMERA_LEFT -> TRACK_LEFT, CAMERA_RIGHT ->
// TRACK_RIGHT). A tracker_command_t on TRACKER_COMMAND restarts one tracker or all of them. The
// heartbeat status names each tracker's state and any input stream that has stopped.
#include <iomanip>
#include <memory>
#include <sstream>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/track_convert.hpp"
#include "nudge/image_t.hpp"
#include "nudge/log.hpp"
#include "nudge/timing.hpp"
#include "nudge/track_t.hpp"
#include "nudge/tracker_command_t.hpp"
#include "nudge/tracking/tracker.hpp"

using namespace nudge;

namespace {

// One camera's tracker and what the heartbeat reports about it.
struct Stream {
  std::string input, output;
  tracking::SymmetryTracker tracker;
  int64_t frames = 0;
  int64_t last_frame_wall_utime = 0;
  Stream(std::string in, std::string out, const tracking::TrackerParams& params)
      : input(std::move(in)), output(std::move(out)), tracker(params) {}
};

// "TRACK_LEFT tracking; TRACK_RIGHT idle, CAMERA_RIGHT stopped 3.0 s ago".
std::string describe(const std::vector<std::unique_ptr<Stream>>& streams, double stale_s) {
  std::ostringstream out;
  const int64_t now = wall_utime();
  for (size_t i = 0; i < streams.size(); ++i) {
    const Stream& s = *streams[i];
    if (i) out << "; ";
    out << s.output << " " << tracking::to_string(s.tracker.status());
    if (s.frames == 0) {
      out << ", no frames on " << s.input << " yet";
    } else {
      const double silent_s = (now - s.last_frame_wall_utime) * 1e-6;
      if (silent_s > stale_s) out << ", " << s.input << " stopped " << std::fixed << std::setprecision(1) << silent_s << " s ago";
    }
  }
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("tracker", [&] {
    bus::Service service("tracker", "Real-time symmetry tracking (thesis ch. 5) of one object per camera.");
    tracking::TrackerParams params;
    std::string inputs = std::string(bus::channel::CAMERA_LEFT) + "," + bus::channel::CAMERA_RIGHT, outputs,
                command_channel = bus::channel::TRACKER_COMMAND;
    double stale_s = 1.0;
    bool no_mask = false;
    auto& f = service.flags();
    f.add_string("inputs", &inputs, "comma-separated image channels, one tracker each");
    f.add_string("outputs", &outputs, "comma-separated track channels (default: CAMERA_X -> TRACK_X)");
    f.add_string("command-channel", &command_channel, "channel of tracker_command_t restart requests");
    f.add_double("stale", &stale_s, "report an input stream as stopped after this many seconds without frames");
    f.add_double("dmin", &params.detector.dmin, "minimum pairing distance, px");
    f.add_double("dmax", &params.detector.dmax, "maximum pairing distance, px (0: none)");
    f.add_double("theta-min", &params.detector.theta_min_deg, "orientation limit before tracking starts, degrees");
    f.add_double("theta-max", &params.detector.theta_max_deg, "orientation limit before tracking starts, degrees");
    f.add_int("max-row-pixels", &params.detector.max_row_pixels, "skip rows of Rot with more edge pixels (0: off)");
    f.add_double("blur", &params.edges.blur_sigma, "Gaussian blur sigma before Canny (0: none)");
    f.add_double("motion-threshold", &params.motion.threshold_factor, "TM: moving if block sum > TM x mean");
    f.add_int("block-size", &params.motion.block_size, "SB: motion block side, px");
    f.add_int("start-min-blocks", &params.start.min_blocks, "moving blocks needed to start tracking");
    f.add_double("gate-sigmas", &params.gate_sigmas, "angle limits = prediction +- this many sigma");
    f.add_int("rearm-frames", &params.start.rearm_frames,
              "after a loss, any motion starts a new track once this many frames passed (0: only a jump)");
    f.add_int("max-missed", &params.max_missed_frames, "predict-only (or held) frames before a track is lost");
    f.add_double("still-fraction", &params.still_fraction,
                 "hold the line when less than this fraction of the track's blocks moves (0 = always predict)");
    f.add_double("support-weight", &params.support_weight,
                 "association: gate error + this * 2 ln(strongest votes / votes) (0 = nearest line)");
    f.add_bool("no-mask", &no_mask, "do not send the block motion mask in track_t");
    if (!service.parse(argc, argv)) return 0;
    const bool send_mask = !no_mask;
    const std::vector<std::string> in_channels = split_list(inputs);
    std::vector<std::string> out_channels = split_list(outputs);
    if (in_channels.empty()) throw FlagError("--inputs names no channel");
    if (!out_channels.empty() && out_channels.size() != in_channels.size())
      throw FlagError("--outputs must name one channel per input");
    if (!(stale_s > 0)) throw FlagError("--stale must be > 0 seconds");
    if (out_channels.empty())
      for (const auto& c : in_channels) out_channels.push_back(bus::channel::derived(c, bus::channel::TRACK));
    std::vector<std::unique_ptr<Stream>> streams;
    try {
      for (size_t i = 0; i < in_channels.size(); ++i)
        streams.push_back(std::make_unique<Stream>(in_channels[i], out_channels[i], params));
    } catch (const std::invalid_argument& e) {
      throw FlagError(e.what());
    }

    service.start();
    service.watch_heartbeats({"camera"});  // its input: say so when the camera goes quiet
    for (auto& stream : streams) {
      Stream* s = stream.get();
      service.subscriptions().subscribe<image_t>(s->input, [&, s, send_mask](const image_t& msg, const std::string&) {
        s->last_frame_wall_utime = wall_utime();
        ++s->frames;
        const cv::Mat image = bus::to_mat(msg);  // throws ImageError naming the image: counted, skipped
        const tracking::TrackState state = s->tracker.feed(image, msg.utime);
        track_t out = bus::to_message(state, msg.utime, msg.frame_id, msg.camera);
        if (!send_mask) {
          out.num_blocks = 0;
          out.motion_mask.clear();
        }
        service.publish(s->output, out);
        log::debug() << s->output << " frame " << msg.frame_id << ": " << tracking::to_string(state.status) << " r "
                     << state.line.r << " theta " << state.line.theta << " " << state.reason << " ("
                     << state.ms.total_ms() << " ms)";
      });
      log::info() << s->input << " -> " << s->output;
    }
    service.subscriptions().subscribe<tracker_command_t>(
        command_channel, [&](const tracker_command_t& cmd, const std::string&) {
          if (cmd.command != tracker_command_t::COMMAND_RESTART)
            throw std::invalid_argument("unknown tracker command " + std::to_string(cmd.command));
          const std::string why = cmd.reason.empty() ? "restart requested" : cmd.reason;
          int matched = 0;
          for (auto& s : streams) {
            if (!cmd.channel.empty() && cmd.channel != s->input && cmd.channel != s->output) continue;
            s->tracker.restart(why);
            ++matched;
          }
          if (matched == 0) throw std::invalid_argument("restart names no tracked channel: " + cmd.channel);
          log::info() << "restarted " << matched << " tracker(s): " << why;
        });
    service.set_status(describe(streams, stale_s));
    return service.run([&] {
      service.set_status(describe(streams, stale_s));
      return 20;
    });
  });
}
