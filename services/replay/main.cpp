// replay: plays an LCM log onto the bus, like lcm-logplayer, but under the operator's control:
// replay_command_t on REPLAY_COMMAND plays, pauses, steps (to the next frame of --step-channels)
// or changes the speed; replay_status_t on REPLAY_STATUS says where it is (4 Hz and at every
// change). nudge-viewer's page sends the commands; scripts/replay.sh runs it. A player, not a
// service: it sends no heartbeat (the viewer's health table shows the log's services), and it
// exits at the end of the log.
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <optional>
#include <set>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/log_file.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/log.hpp"
#include "nudge/replay_command_t.hpp"
#include "nudge/replay_status_t.hpp"
#include "nudge/timing.hpp"
#include "nudge/viewer/replay_pacer.hpp"

using namespace nudge;
namespace channel = nudge::bus::channel;

namespace {

struct LogEvent {
  int64_t timestamp = 0;
  std::string channel;
  std::vector<uint8_t> data;
};

// Reads a log's events one at a time. Throws std::runtime_error naming the path when it cannot
// be opened.
class LogReader {
 public:
  explicit LogReader(const std::string& path) : log_(path, "r") {
    if (!log_.good()) throw std::runtime_error("cannot read the LCM log " + path);
  }
  std::optional<LogEvent> next() {
    const lcm::LogEvent* e = log_.readNextEvent();
    if (!e) return std::nullopt;
    const auto* bytes = static_cast<const uint8_t*>(e->data);
    return LogEvent{e->timestamp, e->channel, std::vector<uint8_t>(bytes, bytes + e->datalen)};
  }

 private:
  lcm::LogFile log_;
};

// One pass over the log for its first and last times and its length (the status reports them),
// and whether it ends in the middle of an event.
struct LogExtent {
  int64_t start = 0, end = 0, events = 0;
  std::string truncation;  // bus::describe_truncation: "" for a whole log
};

LogExtent scan(const std::string& path) {
  const bus::LogScan log = bus::scan_log(path);
  return {log.first_utime, log.last_utime, log.events, bus::describe_truncation(path, log)};
}

class Player {
 public:
  Player(bus::Service& service, std::string path, viewer::ReplayPacer pacer, std::set<std::string> step_channels)
      : service_(service), path_(std::move(path)), extent_(scan(path_)), reader_(path_), pacer_(pacer),
        step_channels_(std::move(step_channels)) {}

  void command(const replay_command_t& cmd) {
    const int64_t now = wall_utime();
    switch (cmd.command) {
      case replay_command_t::COMMAND_PLAY: pacer_.play(now); break;
      case replay_command_t::COMMAND_PAUSE: pacer_.pause(); break;
      case replay_command_t::COMMAND_STEP: pacer_.step(); break;
      case replay_command_t::COMMAND_SPEED: pacer_.set_speed(cmd.speed, now); break;  // throws naming a bad speed
      default: throw std::invalid_argument("unknown replay command " + std::to_string(cmd.command));
    }
    log::info() << "replay " << (pacer_.paused() ? "paused" : "playing") << " at x" << pacer_.speed()
                << (pacer_.stepping() ? ", stepping" : "");
    publish_status();
  }

  // Publishes what is due; returns how many milliseconds to wait for the next event or command
  // (-1: the log is finished).
  int play_due() {
    for (int published = 0; published < 1000; ++published) {  // stay responsive to commands
      if (!pending_) pending_ = reader_.next();
      if (!pending_) {
        finished_ = true;
        publish_status();
        return -1;
      }
      const int64_t now = wall_utime();
      const int64_t wait = pacer_.wait_us(pending_->timestamp, now);
      if (wait != 0) {
        maybe_publish_status(now);
        return wait < 0 ? 50 : static_cast<int>(std::min<int64_t>(50, (wait + 999) / 1000));
      }
      service_.output().publish(pending_->channel, pending_->data.data(), static_cast<unsigned>(pending_->data.size()));
      ++events_;
      const bool was_stepping = pacer_.stepping();
      pacer_.released(pending_->timestamp, step_channels_.count(pending_->channel) > 0, now);
      pending_.reset();
      if (was_stepping && !pacer_.stepping()) publish_status();  // the step is done
    }
    return 0;
  }

  void maybe_publish_status(int64_t now) {
    if (now - last_status_ >= 250000) publish_status();
  }

  void publish_status() {
    replay_status_t status{};
    status.utime = wall_utime();
    status.log = path_;
    status.state = finished_         ? replay_status_t::STATE_FINISHED
                   : pacer_.paused() ? replay_status_t::STATE_PAUSED
                                     : replay_status_t::STATE_PLAYING;
    status.speed = pacer_.speed();
    status.position_utime = pacer_.position() != 0 ? pacer_.position() : extent_.start;
    status.start_utime = extent_.start;
    status.end_utime = extent_.end;
    status.events = events_;
    status.total_events = extent_.events;
    service_.output().publish(channel::REPLAY_STATUS, &status);
    last_status_ = status.utime;
  }

  const LogExtent& extent() const { return extent_; }
  int64_t played() const { return events_; }

 private:
  bus::Service& service_;
  std::string path_;
  LogExtent extent_;
  LogReader reader_;
  viewer::ReplayPacer pacer_;
  std::set<std::string> step_channels_;
  std::optional<LogEvent> pending_;
  int64_t events_ = 0, last_status_ = 0;
  bool finished_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("replay", [&] {
    bus::Service service("replay", "Plays an LCM log onto the bus; pause, step and speed by REPLAY_COMMAND.");
    double speed = 1;
    bool paused = false;
    std::string step_channels = std::string(channel::CAMERA_LEFT) + "," + channel::CAMERA;
    auto& f = service.flags();
    f.set_positional("LOG", "the LCM log to play");
    f.add_double("speed", &speed, "playback speed factor (> 0)");
    f.add_bool("paused", &paused, "start paused (a step or play command starts it)");
    f.add_string("step-channels", &step_channels, "a step plays up to and including the next event on one of these");
    if (!service.parse(argc, argv)) return 0;
    if (f.positional().size() != 1) throw FlagError("give exactly one LOG");
    viewer::ReplayPacer pacer = [&] {
      try {
        return viewer::ReplayPacer(speed, paused);
      } catch (const std::invalid_argument& e) {
        throw FlagError(std::string("--speed: ") + e.what());
      }
    }();
    const std::vector<std::string> steps = split_list(step_channels);
    Player player(service, f.positional()[0], pacer, std::set<std::string>(steps.begin(), steps.end()));
    log::info() << "playing " << f.positional()[0] << ": " << player.extent().events << " events, "
                << (player.extent().end - player.extent().start) * 1e-6 << " s" << (paused ? " (paused)" : "");
    if (!player.extent().truncation.empty()) log::warn() << player.extent().truncation;

    service.start();
    service.subscriptions().subscribe<replay_command_t>(
        channel::REPLAY_COMMAND, [&](const replay_command_t& cmd, const std::string&) { player.command(cmd); });
    player.publish_status();
    int wait_ms = 0;
    while (!service.stop_requested()) {
      if (service.input().handleTimeout(std::max(0, wait_ms)) < 0 && !service.stop_requested())
        throw std::runtime_error("LCM input failed");
      wait_ms = player.play_due();
      if (wait_ms < 0) {
        log::info() << "log finished: " << player.played() << " events played";
        if (!player.extent().truncation.empty()) log::warn() << player.extent().truncation;
        break;
      }
    }
    return 0;
  });
}
