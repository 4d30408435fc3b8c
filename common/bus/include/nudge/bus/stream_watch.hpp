#pragma once
// Noticing that a stream stopped while its sender lives on (a camera whose driver hangs, a video
// file at its end, a paused player): the heartbeat watch sees nothing wrong then, so a service
// that needs a steady input watches the receive times of its channels. A channel heard at least
// once and then quiet for longer than max(kStreamSilentAfterUs, 4 mean intervals) is silent.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace nudge::bus {

// As kSilentAfterUs for heartbeats: a 10 Hz stream that misses 25 frames, a 1 Hz one 2.
constexpr int64_t kStreamSilentAfterUs = 2500000;

class StreamWatch {
 public:
  explicit StreamWatch(int64_t silent_after_us = kStreamSilentAfterUs) : silent_after_us_(silent_after_us) {}

  // receive_utime: when it arrived, on the clock later passed to silent(). A time before the
  // channel's last one (the clock went back) restarts the channel's timing, as its first message.
  void on_message(const std::string& channel, int64_t receive_utime);

  struct Silent {
    std::string channel;
    double seconds = 0;  // since its last message
  };
  // Channels heard at least once and quiet for longer than their limit at now_utime. A now
  // before a channel's last message (the clock went back) is not silence.
  std::vector<Silent> silent(int64_t now_utime) const;

 private:
  struct Timing {
    int64_t last_utime = 0;
    double mean_interval_us = 0;  // running mean of the intervals; 0 until two messages
  };
  int64_t silent_after_us_;
  std::map<std::string, Timing> channels_;
};

// "CAMERA_LEFT silent for 3.1 s, CAMERA_RIGHT silent for 3.1 s"; "" when none is.
std::string describe(const std::vector<StreamWatch::Silent>& silent);

}  // namespace nudge::bus
