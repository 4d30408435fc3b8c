#include "nudge/test/lcm_log.hpp"

#include "nudge/bus/channels.hpp"
#include "nudge/heartbeat_t.hpp"

namespace nudge::test {

LogWriter::LogWriter(const std::string& path) : path_(path), log_(path, "w") {
  if (!log_.good()) throw std::runtime_error("cannot create the log " + path);
}

void LogWriter::raw(int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes) {
  lcm::LogEvent ev{};
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<uint8_t*>(bytes.data());
  if (log_.writeEvent(&ev) != 0) throw std::runtime_error("cannot write an event on " + channel + " to " + path_);
}

void write_event(lcm::LogFile& log, int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes) {
  lcm::LogEvent ev{};
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<uint8_t*>(bytes.data());
  if (log.writeEvent(&ev) != 0) throw std::runtime_error("cannot write an event on " + channel + " to a log");
}

void write_log(const std::string& path, const std::vector<Event>& events) {
  LogWriter log(path);
  for (const Event& e : events) log.write(e);
}

std::vector<Event> read_log(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot read the log " + path);
  std::vector<Event> events;
  for (const lcm::LogEvent* ev = log.readNextEvent(); ev; ev = log.readNextEvent()) {
    const auto* p = static_cast<const uint8_t*>(ev->data);
    events.push_back({ev->timestamp, ev->channel, std::vector<uint8_t>(p, p + ev->datalen)});
  }
  return events;
}

int64_t last_heartbeat_errors(const std::vector<Event>& events) {
  const auto heartbeats = messages_on<heartbeat_t>(events, bus::channel::HEARTBEAT);
  return heartbeats.empty() ? -1 : heartbeats.back().errors;
}

}  // namespace nudge::test
