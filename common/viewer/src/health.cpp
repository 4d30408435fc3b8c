#include "nudge/viewer/health.hpp"

namespace nudge::viewer {

void HealthTable::observe(const Heartbeat& heartbeat) {
  const std::string name = heartbeat.instance.empty() ? heartbeat.service : heartbeat.service + "/" + heartbeat.instance;
  Entry& entry = services_[name];
  // A restarted process (new pid) or a log played again (time going back) starts its rates afresh.
  const bool continues = !entry.last.service.empty() && entry.last.pid == heartbeat.pid &&
                         entry.last.log_time == heartbeat.log_time &&
                         heartbeat.seen_utime > entry.last.seen_utime;
  entry.has_previous = continues;
  if (continues) entry.previous = entry.last;
  entry.last = heartbeat;
}

std::vector<HealthRow> HealthTable::rows(const HealthClock& now) const {
  std::vector<HealthRow> rows;
  for (const auto& [name, entry] : services_) {
    HealthRow row;
    row.name = name;
    row.pid = entry.last.pid;
    row.state = entry.last.state;
    row.errors = entry.last.errors;
    row.status = entry.last.status;
    const int64_t now_utime = entry.last.log_time ? now.log_utime : now.wall_utime;
    row.last_seen_s = (now_utime - entry.last.seen_utime) * 1e-6;
    row.alive = row.last_seen_s <= dead_after_s_;
    if (entry.has_previous) {
      const double dt = (entry.last.seen_utime - entry.previous.seen_utime) * 1e-6;
      row.heartbeat_hz = 1.0 / dt;
      row.in_per_s = (entry.last.messages_in - entry.previous.messages_in) / dt;
      row.out_per_s = (entry.last.messages_out - entry.previous.messages_out) / dt;
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace nudge::viewer
