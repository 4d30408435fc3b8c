#pragma once
// Typed LCM subscriptions for Debian's LCM 1.3.1, which has no lambda subscribe.
// A message that fails to decode (wrong size, truncated, lengths that decode() throws on or that
// exceed the bytes sent: decode.hpp) or whose handler throws is reported naming the channel,
// counted, and skipped; the service keeps running. LCM numbers nothing and drops silently when a
// socket buffer or queue is full, so gaps in a channel's frame_id sequence are counted instead.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nudge/bus/decode.hpp"
#include "nudge/log.hpp"
#include "nudge/sim_state_t.hpp"

namespace nudge::bus {

// A channel's frame_id sequence as received: how many arrived and how many were skipped over.
struct SequenceGaps {
  int64_t last_id = -1;  // -1: none yet
  int64_t received = 0, missed = 0, restarts = 0;  // restarts: the id went back (a source restarted)
};

struct Counters {
  std::atomic<int64_t> messages_in{0};
  std::atomic<int64_t> messages_out{0};
  std::atomic<int64_t> errors{0};
  std::atomic<int64_t> missed{0};  // frame_ids skipped over, all channels together

  // Counts an error and keeps its description for the heartbeat's status.
  void note_error(const std::string& what) {
    ++errors;
    const std::lock_guard<std::mutex> lock(mutex_);
    last_error_ = what;
  }
  std::string last_error() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return last_error_;
  }
  // Records a frame_id received on `channel`; returns how many ids it skipped over.
  int64_t note_frame_id(const std::string& channel, int64_t id) {
    const std::lock_guard<std::mutex> lock(mutex_);
    SequenceGaps& g = gaps_[channel];
    int64_t skipped = 0;
    if (g.last_id >= 0 && id > g.last_id + 1) skipped = id - g.last_id - 1;
    if (g.last_id >= 0 && id <= g.last_id) ++g.restarts;  // a repeat or a restart, not a loss
    ++g.received;
    g.missed += skipped;
    g.last_id = id;
    missed += skipped;
    return skipped;
  }
  std::map<std::string, SequenceGaps> gaps() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return gaps_;
  }

 private:
  mutable std::mutex mutex_;  // handlers and the heartbeat need not share a thread
  std::string last_error_;
  std::map<std::string, SequenceGaps> gaps_;
};

// Messages that carry a per-source sequence number (image_t, symmetry_lines_t, track_t, ...).
template <typename Msg, typename = void>
struct HasFrameId : std::false_type {};
template <typename Msg>
struct HasFrameId<Msg, std::void_t<decltype(std::declval<Msg>().frame_id)>> : std::true_type {};

// Streams: periodic messages of which a newer one supersedes an older one (camera frames and what
// is computed from them, the simulated world's state). A receiver that falls behind a stream is
// better off skipping to the newest than working through a backlog of stale ones; commands,
// requests, states and heartbeats are never skipped that way (they keep LCM's queue of 30).
template <typename Msg>
struct IsStream : HasFrameId<Msg> {};
template <>
struct IsStream<sim_state_t> : std::true_type {};

// Messages LCM holds per stream subscription, received but not yet handled, before it drops new
// ones (LCM's own default is 30). Chosen by measurement (docs/reliability.md, "Soak").
constexpr int kDefaultQueueCapacity = 3;

class Subscriptions {
 public:
  Subscriptions(lcm::LCM& lcm, Counters& counters) : lcm_(lcm), counters_(counters) {}
  Subscriptions(const Subscriptions&) = delete;
  Subscriptions& operator=(const Subscriptions&) = delete;
  ~Subscriptions() {
    for (auto& h : handlers_) lcm_.unsubscribe(h->subscription);
  }

  // handler(msg, channel). Returns nothing; errors are logged and counted.
  template <typename Msg>
  void subscribe(const std::string& channel,
                 std::function<void(const Msg&, const std::string& channel)> handler) {
    subscribe_timed<Msg>(channel, [handler = std::move(handler)](const Msg& msg, const std::string& ch, int64_t) {
      handler(msg, ch);
    });
  }

  // handler(msg, channel, receive_utime): LCM's receive time, wall-clock microseconds on every
  // provider (a played log's events are stamped as they are read). Logic that must replay
  // deterministically uses the message's own utime instead.
  template <typename Msg>
  void subscribe_timed(const std::string& channel,
                       std::function<void(const Msg&, const std::string& channel, int64_t receive_utime)> handler) {
    auto h = std::make_unique<Typed<Msg>>(std::move(handler), counters_, tap_);
    typed_channels_.push_back(channel);
    h->subscription = lcm_.subscribe(channel, &Typed<Msg>::on_raw, h.get());
    h->stream = IsStream<Msg>::value;
    if (h->stream && stream_queue_capacity_ >= 0) h->subscription->setQueueCapacity(stream_queue_capacity_);
    handlers_.push_back(std::move(h));
  }

  // Messages held per stream subscription (IsStream) before LCM drops new ones (0: no limit), for
  // the subscriptions made so far and those to come. Untouched, LCM's default (30) holds.
  void set_stream_queue_capacity(int messages) {
    if (messages < 0) throw std::invalid_argument("queue capacity must be >= 0, not " + std::to_string(messages));
    stream_queue_capacity_ = messages;
    for (auto& h : handlers_)
      if (h->stream) h->subscription->setQueueCapacity(messages);
  }

  // tap(rbuf, channel) for every message a typed handler is given, just before it is decoded and
  // handled (malformed ones too): a recorder that must hold exactly what the handlers saw, in the
  // order they saw it. LCM keeps a queue per subscription and drops per subscription when one is
  // full, so a separate catch-all subscription would log messages a stream handler skipped and
  // miss ones it handled (docs/supervisor.md, "The run's log").
  using Tap = std::function<void(const lcm::ReceiveBuffer* rbuf, const std::string& channel)>;
  void set_tap(Tap tap) { tap_ = std::move(tap); }
  // Whether a typed subscription was made on exactly this channel name.
  bool has_typed(const std::string& channel) const {
    for (const std::string& c : typed_channels_)
      if (c == channel) return true;
    return false;
  }

  // handler(channel, receive_utime) for every message on `channel`, undecoded and uncounted:
  // for watching a stream's timing (StreamWatch) next to the subscription that reads it.
  void on_receive(const std::string& channel, std::function<void(const std::string& channel, int64_t receive_utime)> handler) {
    auto h = std::make_unique<Raw>();
    h->fn = std::move(handler);
    h->subscription = lcm_.subscribe(channel, &Raw::on_raw, h.get());
    handlers_.push_back(std::move(h));
  }

 private:
  struct Base {
    virtual ~Base() = default;
    lcm::Subscription* subscription = nullptr;
    bool stream = false;  // IsStream: its queue is stream_queue_capacity_
  };
  struct Raw : Base {
    void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) { fn(channel, rbuf->recv_utime); }
    std::function<void(const std::string&, int64_t)> fn;
  };
  template <typename Msg>
  struct Typed : Base {
    using Handler = std::function<void(const Msg&, const std::string&, int64_t)>;
    Typed(Handler f, Counters& c, const Tap& t) : fn(std::move(f)), counters(c), tap(t) {}
    void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      ++counters.messages_in;
      if (tap) tap(rbuf, channel);
      Msg msg;
      const std::string problem = decode_message(rbuf->data, static_cast<int>(rbuf->data_size), &msg);
      if (!problem.empty()) {
        const std::string what = "skipped a malformed message on " + channel + ": " + problem;
        counters.note_error(what);
        log::error() << what;
        return;
      }
      if constexpr (HasFrameId<Msg>::value) {
        const int64_t skipped = counters.note_frame_id(channel, msg.frame_id);
        if (skipped > 0 && rbuf->recv_utime >= next_gap_warning) {  // at most one line a second
          log::warn() << channel << ": " << skipped << " message(s) missing before frame " << msg.frame_id
                      << " (dropped by the network or a slow receiver; totals in the heartbeat)";
          next_gap_warning = rbuf->recv_utime + 1000000;
        }
      }
      try {
        fn(msg, channel, rbuf->recv_utime);
      } catch (const std::exception& e) {
        const std::string what = "skipped a message on " + channel + ": " + e.what();
        counters.note_error(what);
        log::error() << what;
      }
    }
    Handler fn;
    Counters& counters;
    const Tap& tap;  // the Subscriptions' own: set_tap() reaches the subscriptions made before it
    int64_t next_gap_warning = 0;
  };

  lcm::LCM& lcm_;
  Counters& counters_;
  std::vector<std::unique_ptr<Base>> handlers_;
  std::vector<std::string> typed_channels_;
  Tap tap_;
  int stream_queue_capacity_ = -1;  // -1: LCM's default
};

}  // namespace nudge::bus
