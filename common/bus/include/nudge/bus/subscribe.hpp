#pragma once
// Typed LCM subscriptions for Debian's LCM 1.3.1, which has no lambda subscribe.
// A message that fails to decode (wrong size, truncated, lengths that decode() throws on or that
// exceed the bytes sent: decode.hpp) or whose handler throws is reported naming the channel,
// counted, and skipped; the service keeps running.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "nudge/bus/decode.hpp"
#include "nudge/log.hpp"

namespace nudge::bus {

struct Counters {
  std::atomic<int64_t> messages_in{0};
  std::atomic<int64_t> messages_out{0};
  std::atomic<int64_t> errors{0};
};

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
    auto h = std::make_unique<Typed<Msg>>(std::move(handler), counters_);
    h->subscription = lcm_.subscribe(channel, &Typed<Msg>::on_raw, h.get());
    handlers_.push_back(std::move(h));
  }

 private:
  struct Base {
    virtual ~Base() = default;
    lcm::Subscription* subscription = nullptr;
  };
  template <typename Msg>
  struct Typed : Base {
    using Handler = std::function<void(const Msg&, const std::string&, int64_t)>;
    Typed(Handler f, Counters& c) : fn(std::move(f)), counters(c) {}
    void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      ++counters.messages_in;
      Msg msg;
      const std::string problem = decode_message(rbuf->data, static_cast<int>(rbuf->data_size), &msg);
      if (!problem.empty()) {
        ++counters.errors;
        log::error() << "skipped a malformed message on " << channel << ": " << problem;
        return;
      }
      try {
        fn(msg, channel, rbuf->recv_utime);
      } catch (const std::exception& e) {
        ++counters.errors;
        log::error() << "skipped a message on " << channel << ": " << e.what();
      }
    }
    Handler fn;
    Counters& counters;
  };

  lcm::LCM& lcm_;
  Counters& counters_;
  std::vector<std::unique_ptr<Base>> handlers_;
};

}  // namespace nudge::bus
