#pragma once
// The shell every service runs in: flags (--lcm-url, --lcm-in, --lcm-out, --instance, --verbose),
// LCM set-up, a heartbeat on channel::HEARTBEAT once a second, and a loop that ends cleanly on SIGINT or
// SIGTERM, or when an input log (file:// provider) is exhausted.
//
// The transport is injectable so that a test can run a service's handlers in its own process:
// start(lcm) on an lcm::LCM the test owns (LCM's in-process "memq://" provider: no sockets), then
// publish to it and pump with handle_pending() instead of run()'s wall-clock loop.
#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <memory>
#include <string>

#include "nudge/bus/heartbeat_watch.hpp"
#include "nudge/bus/stream_watch.hpp"
#include "nudge/bus/subscribe.hpp"
#include "nudge/flags.hpp"
#include "nudge/heartbeat_t.hpp"

namespace nudge::bus {

// ttl=0 keeps default traffic on this host; override with --lcm-url for a real network.
// recv_buf_size: a 300 KB image does not fit the kernel's default socket buffer (208 KB), and
// LCM drops what does not fit silently; 4 MB holds a second of 640x480 stereo at 10 Hz. The
// kernel caps it at net.core.rmem_max (LCM then prints a warning naming both sizes).
constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

// A heartbeat stays DEGRADED this long after the last bad input, missed frame or silent peer,
// then recovers to RUNNING.
constexpr int64_t kDegradedHoldUs = 5000000;

class Service {
 public:
  Service(std::string name, std::string summary);
  ~Service();

  Flags& flags() { return flags_; }
  // Parses the command line. Returns false when --help was printed. Throws FlagError.
  bool parse(int argc, char** argv);
  // Opens the LCM input and output the flags name. Throws std::runtime_error naming a bad URL.
  void start();
  // Opens these URLs instead of the flags' (an empty out_url: the input's). E.g. "memq://".
  void start(const std::string& in_url, const std::string& out_url);
  // Runs on transports the caller owns, which must outlive the service (output: null for the
  // input's). Installs no signal handlers: the caller's process is not a service binary.
  void start(lcm::LCM& input, lcm::LCM* output = nullptr);

  lcm::LCM& input() { return *in_; }
  lcm::LCM& output() { return *out_; }
  Subscriptions& subscriptions() { return *subscriptions_; }
  Counters& counters() { return counters_; }
  const std::string& name() const { return name_; }
  bool input_is_log() const;

  template <typename Msg>
  void publish(const std::string& channel, const Msg& msg) {
    output().publish(channel, &msg);
    ++counters_.messages_out;
  }

  // Handles messages until stopped. `tick` runs after every wait for messages (at most wait_ms
  // long) and may call request_stop(); a tick returning a shorter wait shortens the next one.
  // Returns the process exit code.
  int run(const std::function<int()>& tick = {}, int wait_ms = 20);
  // Handles the messages already queued on the input, without waiting, so a test pumps the bus
  // deterministically. Messages the handlers publish to a shared memq:// bus are handled in the
  // same call when the service subscribes to them. Stops after max_messages (a handler that feeds
  // itself cannot loop forever). Returns how many were handled. Throws std::runtime_error when
  // the input fails.
  int handle_pending(int max_messages = 10000);
  // Waits up to timeout_ms for one message and handles it. Returns whether one was handled.
  bool spin_once(int timeout_ms = 0);
  // Publishes a heartbeat with the current counters and status (run() does once a second):
  // DEGRADED within kDegradedHoldUs of an error, a missed frame or a silent watched service, else
  // RUNNING. `status` is the service's own (set_status) followed by what went wrong, or "ok".
  void publish_heartbeat() { publish_heartbeat_at(wall_utime_now()); }
  // The same at a given wall-clock time (tests step time instead of sleeping).
  void publish_heartbeat_at(int64_t now_utime);

  // Watches the HEARTBEAT of these services (all others when empty), after start(): one that was
  // heard and then stays silent for kSilentAfterUs is logged, named in the status and makes this
  // service DEGRADED until it is heard again. Does nothing when the input is a log.
  void watch_heartbeats(std::vector<std::string> services = {});
  // What watch_heartbeats() finds silent at now_utime; logs sources that went silent or came back.
  std::vector<HeartbeatWatch::Silent> check_heartbeats(int64_t now_utime);

  // Watches the receive times of these channels (a camera's frames), after start(): one that was
  // heard and then stays quiet (StreamWatch: 2.5 s or 4 of its mean intervals) is logged, named
  // in the status ("CAMERA_LEFT silent for 3.1 s") and makes this service DEGRADED until its
  // messages come again. For streams that should be steady, not for requested stills. Does
  // nothing when the input is a log (a log's pace is the player's).
  void watch_streams(const std::vector<std::string>& channels);
  // What watch_streams() finds silent at now_utime; logs channels that went silent or came back.
  std::vector<StreamWatch::Silent> check_streams(int64_t now_utime);

  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const;
  void set_status(const std::string& status) { status_ = status; }

 private:
  void publish_heartbeat(int8_t state, int64_t now_utime);
  void attach(lcm::LCM& input, lcm::LCM& output);
  static int64_t wall_utime_now();
  // At the end of an input log: warns when it ended in the middle of an event (LCM stops silently).
  void report_truncated_input() const;
  std::string describe_status(const std::vector<HeartbeatWatch::Silent>& silent,
                              const std::vector<StreamWatch::Silent>& quiet) const;

  std::string name_;
  Flags flags_;
  std::string lcm_url_ = kDefaultLcmUrl, lcm_in_, lcm_out_, instance_;
  bool verbose_ = false;
  int queue_capacity_ = kDefaultQueueCapacity;  // --queue: on a network input only
  std::unique_ptr<lcm::LCM> owned_in_, owned_out_;  // when start() opened the URLs itself
  lcm::LCM* in_ = nullptr;
  lcm::LCM* out_ = nullptr;
  std::unique_ptr<Subscriptions> subscriptions_;
  Counters counters_;
  std::string status_;
  bool stop_requested_ = false;
  std::unique_ptr<HeartbeatWatch> watch_;
  std::string reported_silent_;      // what check_heartbeats() last logged
  std::unique_ptr<StreamWatch> streams_;
  std::string reported_quiet_;       // what check_streams() last logged
  int64_t problems_seen_ = 0;        // errors + missed frames at the last heartbeat
  int64_t last_problem_utime_ = -1;  // when that count last grew, or a watched service was silent
};

// Runs `body` and turns flag errors into a usage message and exit code 2, other exceptions into
// an error message and exit code 1. First keeps the process's freed images for reuse
// (nudge/memory.hpp: no page faults for each new frame's buffers).
int guarded_main(const std::string& name, const std::function<int()>& body);

}  // namespace nudge::bus
