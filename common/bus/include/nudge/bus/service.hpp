#pragma once
// The shell every service runs in: flags (--lcm-url, --lcm-in, --lcm-out, --instance, --verbose),
// LCM set-up, a heartbeat on channel::HEARTBEAT once a second, and a loop that ends cleanly on SIGINT or
// SIGTERM, or when an input log (file:// provider) is exhausted.
#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <memory>
#include <string>

#include "nudge/bus/subscribe.hpp"
#include "nudge/flags.hpp"

namespace nudge::bus {

// ttl=0 keeps default traffic on this host; override with --lcm-url for a real network.
constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

class Service {
 public:
  Service(std::string name, std::string summary);
  ~Service();

  Flags& flags() { return flags_; }
  // Parses the command line. Returns false when --help was printed. Throws FlagError.
  bool parse(int argc, char** argv);
  // Opens the LCM input and output. Throws std::runtime_error naming a bad URL.
  void start();

  lcm::LCM& input() { return *in_; }
  lcm::LCM& output() { return out_ ? *out_ : *in_; }
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
  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const;
  void set_status(const std::string& status) { status_ = status; }

 private:
  void publish_heartbeat(int8_t state);

  std::string name_;
  Flags flags_;
  std::string lcm_url_ = kDefaultLcmUrl, lcm_in_, lcm_out_, instance_;
  bool verbose_ = false;
  std::unique_ptr<lcm::LCM> in_, out_;
  std::unique_ptr<Subscriptions> subscriptions_;
  Counters counters_;
  std::string status_;
  bool stop_requested_ = false;
};

// Runs `body` and turns flag errors into a usage message and exit code 2, other exceptions into
// an error message and exit code 1.
int guarded_main(const std::string& name, const std::function<int()>& body);

}  // namespace nudge::bus
