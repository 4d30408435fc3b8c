#include "nudge/bus/stream_watch.hpp"

#include <algorithm>
#include <cstdio>

namespace nudge::bus {

namespace {
constexpr double kMeanWeight = 0.1;        // of the newest interval in the running mean
constexpr double kIntervalsBeforeSilent = 4;  // a slow stream (1 Hz) is not silent after one late frame
}  // namespace

void StreamWatch::on_message(const std::string& channel, int64_t receive_utime) {
  const auto found = channels_.find(channel);
  if (found == channels_.end() || receive_utime < found->second.last_utime) {
    channels_[channel] = Timing{receive_utime, 0};  // first heard, or the clock went back
    return;
  }
  Timing& t = found->second;
  const double interval = static_cast<double>(receive_utime - t.last_utime);
  t.mean_interval_us = t.mean_interval_us == 0 ? interval : (1 - kMeanWeight) * t.mean_interval_us + kMeanWeight * interval;
  t.last_utime = receive_utime;
}

std::vector<StreamWatch::Silent> StreamWatch::silent(int64_t now_utime) const {
  std::vector<Silent> out;
  for (const auto& [channel, t] : channels_) {
    const double quiet = static_cast<double>(now_utime - t.last_utime);
    const double limit = std::max(static_cast<double>(silent_after_us_), kIntervalsBeforeSilent * t.mean_interval_us);
    if (quiet > limit) out.push_back({channel, quiet / 1e6});
  }
  return out;
}

std::string describe(const std::vector<StreamWatch::Silent>& silent) {
  std::string text;
  for (const auto& s : silent) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.1f", s.seconds);
    text += (text.empty() ? "" : ", ") + s.channel + " silent for " + seconds + " s";
  }
  return text;
}

}  // namespace nudge::bus
