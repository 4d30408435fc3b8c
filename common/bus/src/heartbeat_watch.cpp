#include "nudge/bus/heartbeat_watch.hpp"

#include <algorithm>
#include <cstdio>

namespace nudge::bus {

HeartbeatWatch::HeartbeatWatch(std::vector<std::string> services, int32_t own_pid, int64_t silent_after_us)
    : services_(std::move(services)), own_pid_(own_pid), silent_after_us_(silent_after_us) {}

bool HeartbeatWatch::watched(const std::string& service) const {
  return services_.empty() || std::find(services_.begin(), services_.end(), service) != services_.end();
}

void HeartbeatWatch::on_heartbeat(const heartbeat_t& heartbeat, int64_t receive_utime) {
  if (heartbeat.pid == own_pid_ || !watched(heartbeat.service)) return;
  const std::string source = heartbeat.instance.empty() || heartbeat.instance == heartbeat.service
                                 ? heartbeat.service
                                 : heartbeat.service + "/" + heartbeat.instance;
  if (heartbeat.state == heartbeat_t::STATE_STOPPING) last_seen_.erase(source);  // a goodbye
  else last_seen_[source] = receive_utime;
}

std::vector<HeartbeatWatch::Silent> HeartbeatWatch::silent(int64_t now_utime) const {
  std::vector<Silent> out;
  for (const auto& [source, seen] : last_seen_)
    if (now_utime - seen > silent_after_us_) out.push_back({source, (now_utime - seen) / 1e6});
  return out;
}

std::string describe(const std::vector<HeartbeatWatch::Silent>& silent) {
  std::string text;
  for (const auto& s : silent) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.1f", s.seconds);
    text += (text.empty() ? "" : ", ") + s.source + " silent for " + seconds + " s";
  }
  return text;
}

}  // namespace nudge::bus
