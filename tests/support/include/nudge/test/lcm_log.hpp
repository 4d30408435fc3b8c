#pragma once
// LCM logs in tests: write typed messages (and deliberately malformed bytes) into an input log,
// read an output log back by channel and type. LCM's file provider plays these logs to a service.
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace nudge::test {

// The bytes of a message, as LCM sends them.
template <typename Msg>
std::vector<uint8_t> encode(const Msg& msg) {
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// One logged message: its timestamp (the log's clock), channel and encoded bytes.
struct Event {
  int64_t timestamp = 0;
  std::string channel;
  std::vector<uint8_t> data;
};

// Decodes an event as Msg. Throws std::runtime_error naming the channel and type when it does not.
template <typename Msg>
Msg decode(const Event& event) {
  Msg msg;
  if (msg.decode(event.data.data(), 0, static_cast<int>(event.data.size())) < 0)
    throw std::runtime_error("a message on " + event.channel + " does not decode as " + Msg::getTypeName());
  return msg;
}

// The messages on `channel`, in log order, decoded as Msg.
template <typename Msg>
std::vector<Msg> messages_on(const std::vector<Event>& events, const std::string& channel) {
  std::vector<Msg> out;
  for (const Event& e : events)
    if (e.channel == channel) out.push_back(decode<Msg>(e));
  return out;
}

// A log being written, in time order (LCM's file provider plays it in file order).
class LogWriter {
 public:
  // Throws std::runtime_error naming the path when it cannot be created.
  explicit LogWriter(const std::string& path);
  // Any bytes, e.g. a truncated message that a service must report and skip.
  void raw(int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes);
  template <typename Msg>
  void write(int64_t utime, const std::string& channel, const Msg& msg) {
    raw(utime, channel, encode(msg));
  }
  void write(const Event& event) { raw(event.timestamp, event.channel, event.data); }

 private:
  std::string path_;
  lcm::LogFile log_;
};

// Appends one event to a log opened for writing. Throws std::runtime_error when it cannot.
void write_event(lcm::LogFile& log, int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes);
// Writes these events as a new log at `path`.
void write_log(const std::string& path, const std::vector<Event>& events);
// Every event of the log at `path`. Throws std::runtime_error naming the path when it cannot be read.
std::vector<Event> read_log(const std::string& path);
// The messages on `channel` of the log at `path`, decoded as Msg.
template <typename Msg>
std::vector<Msg> read_messages(const std::string& path, const std::string& channel) {
  return messages_on<Msg>(read_log(path), channel);
}

// The `errors` count of the last HEARTBEAT in the events (-1 when there is none).
int64_t last_heartbeat_errors(const std::vector<Event>& events);

}  // namespace nudge::test
