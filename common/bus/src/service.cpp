#include "nudge/bus/service.hpp"

#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <iostream>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/log_file.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/log.hpp"
#include "nudge/memory.hpp"
#include "nudge/timing.hpp"

namespace nudge::bus {

namespace {
volatile std::sig_atomic_t g_signalled = 0;
void on_signal(int) { g_signalled = 1; }
}  // namespace

Service::Service(std::string name, std::string summary)
    : name_(std::move(name)), flags_("nudge-" + name_, std::move(summary)) {
  log::set_component(name_);
  flags_.add_string("lcm-url", &lcm_url_, "LCM URL for input and output");
  flags_.add_string("lcm-in", &lcm_in_, "LCM URL to read from (e.g. file://in.lcmlog?speed=0); default --lcm-url");
  flags_.add_string("lcm-out", &lcm_out_, "LCM URL to publish to (e.g. file://out.lcmlog?mode=w); default --lcm-url");
  flags_.add_string("instance", &instance_, "instance name in heartbeats");
  flags_.add_bool("verbose", &verbose_, "log every message");
  flags_.add_int("queue", &queue_capacity_,
                 "on a udpm:// input: messages of a stream (images, lines, tracks, SIM_STATE) held per subscription "
                 "before new ones are dropped (0: no limit)");
}

Service::~Service() {
  subscriptions_.reset();
}

bool Service::parse(int argc, char** argv) {
  if (!flags_.parse(argc, argv)) return false;
  if (verbose_) log::set_level(log::Level::Debug);
  if (instance_.empty()) instance_ = name_;
  if (queue_capacity_ < 0) throw FlagError("--queue must be >= 0 (0: no limit), not " + std::to_string(queue_capacity_));
  return true;
}

bool Service::input_is_log() const {
  const std::string& url = lcm_in_.empty() ? lcm_url_ : lcm_in_;
  return url.rfind("file://", 0) == 0;
}

void Service::start() {
  start(lcm_in_.empty() ? lcm_url_ : lcm_in_, lcm_out_.empty() ? lcm_url_ : lcm_out_);
}

void Service::start(const std::string& in_url, const std::string& requested_out_url) {
  const std::string out_url = requested_out_url.empty() ? in_url : requested_out_url;
  subscriptions_.reset();  // before a previous start()'s LCM goes: they unsubscribe from it
  owned_in_ = std::make_unique<lcm::LCM>(in_url);
  if (!owned_in_->good()) throw std::runtime_error("cannot open LCM input '" + in_url + "'");
  if (out_url != in_url) {
    owned_out_ = std::make_unique<lcm::LCM>(out_url);
    if (!owned_out_->good()) throw std::runtime_error("cannot open LCM output '" + out_url + "'");
  }
  attach(*owned_in_, owned_out_ ? *owned_out_ : *owned_in_);
  // Only a live network input drops what a slow receiver cannot hold; a log (file://) or an
  // in-process bus (memq://, tests that publish a burst and then pump) keeps LCM's default.
  if (in_url.rfind("udpm://", 0) == 0) subscriptions_->set_stream_queue_capacity(queue_capacity_);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  log::info() << "started: in " << in_url << ", out " << out_url;
}

void Service::start(lcm::LCM& input, lcm::LCM* output) {
  if (!input.good()) throw std::runtime_error("the LCM input given to service " + name_ + " is not open");
  if (output && !output->good()) throw std::runtime_error("the LCM output given to service " + name_ + " is not open");
  attach(input, output ? *output : input);
  log::info() << "started on the caller's LCM";
}

void Service::attach(lcm::LCM& input, lcm::LCM& output) {
  if (instance_.empty()) instance_ = name_;  // parse() was not called: no command line
  subscriptions_.reset();  // unsubscribes from a previous start()'s input
  in_ = &input;
  out_ = &output;
  subscriptions_ = std::make_unique<Subscriptions>(*in_, counters_);
}

int Service::handle_pending(int max_messages) {
  int handled = 0;
  while (handled < max_messages && spin_once(0)) ++handled;
  return handled;
}

bool Service::spin_once(int timeout_ms) {
  if (!in_) throw std::logic_error("service " + name_ + ": spin_once() before start()");
  const int rc = in_->handleTimeout(std::max(0, timeout_ms));
  if (rc < 0) throw std::runtime_error("service " + name_ + ": LCM input failed");
  return rc > 0;
}

bool Service::stop_requested() const { return stop_requested_ || g_signalled; }

int64_t Service::wall_utime_now() { return wall_utime(); }

void Service::watch_heartbeats(std::vector<std::string> services) {
  if (!subscriptions_) throw std::logic_error("service " + name_ + ": watch_heartbeats() before start()");
  if (input_is_log()) return;  // a log's heartbeats come at the log's pace, not the senders'
  watch_ = std::make_unique<HeartbeatWatch>(std::move(services), static_cast<int32_t>(getpid()));
  subscriptions_->subscribe_timed<heartbeat_t>(
      channel::HEARTBEAT, [this](const heartbeat_t& hb, const std::string&, int64_t receive_utime) {
        watch_->on_heartbeat(hb, receive_utime);
      });
}

std::vector<HeartbeatWatch::Silent> Service::check_heartbeats(int64_t now_utime) {
  if (!watch_ || input_is_log()) return {};
  auto silent = watch_->silent(now_utime);
  std::string names;
  for (const auto& s : silent) names += s.source + " ";
  if (names != reported_silent_) {  // log changes only, not every tick
    if (!silent.empty()) log::warn() << "no heartbeat: " << describe(silent) << " (stopped or hung?)";
    else log::info() << "every watched service is sending heartbeats again";
    reported_silent_ = names;
  }
  if (!silent.empty()) last_problem_utime_ = now_utime;
  return silent;
}

void Service::watch_streams(const std::vector<std::string>& channels) {
  if (!subscriptions_) throw std::logic_error("service " + name_ + ": watch_streams() before start()");
  if (input_is_log()) return;
  if (!streams_) streams_ = std::make_unique<StreamWatch>();
  for (const std::string& channel : channels)
    subscriptions_->on_receive(channel, [this](const std::string& ch, int64_t receive_utime) {
      streams_->on_message(ch, receive_utime);
    });
}

std::vector<StreamWatch::Silent> Service::check_streams(int64_t now_utime) {
  if (!streams_ || input_is_log()) return {};
  auto quiet = streams_->silent(now_utime);
  std::string names;
  for (const auto& q : quiet) names += q.channel + " ";
  if (names != reported_quiet_) {  // log changes only, not every tick
    if (!quiet.empty()) log::warn() << "no messages: " << describe(quiet) << " (stream stalled or ended?)";
    else log::info() << "every watched stream is flowing again";
    reported_quiet_ = names;
  }
  if (!quiet.empty()) last_problem_utime_ = now_utime;
  return quiet;
}

std::string Service::describe_status(const std::vector<HeartbeatWatch::Silent>& silent,
                                     const std::vector<StreamWatch::Silent>& quiet) const {
  std::string text = status_;
  const auto add = [&text](const std::string& part) { text += (text.empty() ? "" : "; ") + part; };
  if (!silent.empty()) add(describe(silent));
  if (!quiet.empty()) add(describe(quiet));
  for (const auto& [channel, g] : counters_.gaps())
    if (g.missed > 0)
      add(channel + " missed " + std::to_string(g.missed) + " of " + std::to_string(g.missed + g.received));
  if (counters_.errors > 0) {
    std::string last = counters_.last_error();
    if (last.size() > 160) last = last.substr(0, 157) + "...";
    add(std::to_string(counters_.errors) + " errors" + (last.empty() ? "" : ", last: " + last));
  }
  return text.empty() ? "ok" : text;
}

void Service::publish_heartbeat_at(int64_t now_utime) {
  check_heartbeats(now_utime);
  check_streams(now_utime);
  const int64_t problems = counters_.errors + counters_.missed;
  if (problems != problems_seen_) {
    problems_seen_ = problems;
    last_problem_utime_ = now_utime;
  }
  // A clock that went back would hold DEGRADED until it caught up again: the hold restarts.
  if (last_problem_utime_ > now_utime) last_problem_utime_ = now_utime;
  const bool degraded = last_problem_utime_ >= 0 && now_utime - last_problem_utime_ < kDegradedHoldUs;
  publish_heartbeat(degraded ? heartbeat_t::STATE_DEGRADED : heartbeat_t::STATE_RUNNING, now_utime);
}

void Service::publish_heartbeat(int8_t state, int64_t now_utime) {
  heartbeat_t hb;
  hb.utime = now_utime;
  hb.service = name_;
  hb.instance = instance_;
  hb.pid = static_cast<int32_t>(getpid());
  hb.state = state;
  hb.messages_in = counters_.messages_in;
  hb.messages_out = counters_.messages_out;
  hb.errors = counters_.errors;
  const bool live = !input_is_log();
  hb.status = describe_status(watch_ && live ? watch_->silent(now_utime) : std::vector<HeartbeatWatch::Silent>{},
                              streams_ && live ? streams_->silent(now_utime) : std::vector<StreamWatch::Silent>{});
  output().publish(channel::HEARTBEAT, &hb);
}

int Service::run(const std::function<int()>& tick, int wait_ms) {
  const bool from_log = input_is_log();
  publish_heartbeat(heartbeat_t::STATE_RUNNING, wall_utime());
  int64_t next_heartbeat = wall_utime() + 1000000;
  int exit_code = 0;
  int wait = wait_ms;
  while (!stop_requested()) {
    const int rc = in_->handleTimeout(std::max(0, wait));
    if (rc < 0) {
      if (stop_requested()) break;  // a signal interrupted the wait
      if (from_log) {
        log::info() << "input log finished";
        report_truncated_input();
      } else {
        log::error() << "LCM input failed";
        exit_code = 1;
      }
      break;
    }
    wait = tick ? std::min(wait_ms, tick()) : wait_ms;
    const int64_t now = wall_utime();
    check_heartbeats(now);  // a silent peer or stream is logged when noticed, not at the next heartbeat
    check_streams(now);
    if (now >= next_heartbeat) {
      publish_heartbeat_at(now);
      next_heartbeat = now + 1000000;
    }
  }
  publish_heartbeat(heartbeat_t::STATE_STOPPING, wall_utime());
  log::info() << "stopping: " << counters_.messages_in << " in, " << counters_.messages_out << " out, "
              << counters_.errors << " errors";
  return exit_code;
}

void Service::report_truncated_input() const {
  const std::string path = log_path_of_url(lcm_in_.empty() ? lcm_url_ : lcm_in_);
  if (path.empty()) return;
  try {
    const std::string cut = describe_truncation(path, scan_log(path));
    if (!cut.empty()) log::warn() << cut;
  } catch (const std::runtime_error& e) {
    log::warn() << "cannot check the input log's end: " << e.what();
  }
}

int guarded_main(const std::string& name, const std::function<int()>& body) {
  log::set_component(name);
  keep_large_buffers_for_reuse();  // images freed and allocated again, frame after frame: no page faults
  try {
    return body();
  } catch (const FlagError& e) {
    std::cerr << "nudge-" << name << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    log::error() << e.what();
    return 1;
  }
}

}  // namespace nudge::bus
