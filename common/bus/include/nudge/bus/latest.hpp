#pragma once
// The newest message on a channel, for services that act on the latest state of another one
// (the arm's world state, a tracker's last track) instead of on every message.
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include "nudge/bus/subscribe.hpp"

namespace nudge::bus {

template <typename Msg>
class Latest {
 public:
  // Subscribes to `channel` through `subscriptions`: messages that do not decode are counted
  // there and leave the held one unchanged. The subscription may outlive this holder.
  Latest(Subscriptions& subscriptions, const std::string& channel)
      : state_(std::make_shared<State>()), channel_(channel) {
    subscriptions.subscribe_timed<Msg>(
        channel, [state = state_](const Msg& msg, const std::string&, int64_t receive_utime) {
          std::lock_guard<std::mutex> lock(state->mutex);
          state->message = msg;
          state->receive_utime = receive_utime;
          ++state->count;
        });
  }

  const std::string& channel() const { return channel_; }
  bool has() const { return count() > 0; }
  // Messages received so far.
  int64_t count() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    return state_->count;
  }
  // A copy of the newest message. Throws std::logic_error naming the channel before the first.
  Msg get() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    require_message();
    return state_->message;
  }
  // LCM's receive time of the newest message: wall-clock microseconds, also when the input is a
  // log (the file provider stamps events as it plays them, not with their logged time).
  int64_t receive_utime() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    require_message();
    return state_->receive_utime;
  }
  // How long ago the newest message arrived, on the clock `now_utime` comes from.
  int64_t age(int64_t now_utime) const { return now_utime - receive_utime(); }

 private:
  struct State {
    mutable std::mutex mutex;
    Msg message{};
    int64_t receive_utime = 0;
    int64_t count = 0;
  };

  void require_message() const {
    if (state_->count == 0) throw std::logic_error("no message received yet on " + channel_);
  }

  std::shared_ptr<State> state_;
  std::string channel_;
};

}  // namespace nudge::bus
