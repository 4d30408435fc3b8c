#pragma once
// Helpers the service tests share for writing LCM input logs (LCM's file provider reads them).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
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

// Appends one event (possibly deliberately malformed bytes) to a log opened for writing.
inline void write_event(lcm::LogFile& log, int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes) {
  lcm::LogEvent ev{};
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<uint8_t*>(bytes.data());
  ASSERT_EQ(log.writeEvent(&ev), 0);
}

}  // namespace nudge::test
