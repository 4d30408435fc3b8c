#include "nudge/bus/log_file.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace nudge::bus {

LogScan scan_log(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  lcm::LogFile log(path, "r");
  if (ec || !log.good()) throw std::runtime_error("cannot read the LCM log " + path);
  LogScan scan;
  scan.file_bytes = static_cast<int64_t>(size);
  // LCM reads an event's header, channel and data and nothing more: the file position after a
  // whole event is where it ends.
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (scan.events++ == 0) scan.first_utime = e->timestamp;
    scan.last_utime = e->timestamp;
    scan.whole_bytes = static_cast<int64_t>(std::ftell(log.getFilePtr()));
  }
  return scan;
}

std::string describe_truncation(const std::string& path, const LogScan& scan) {
  if (!scan.truncated()) return "";
  return path + " ends in the middle of an event: the last " + std::to_string(scan.file_bytes - scan.whole_bytes) +
         " of " + std::to_string(scan.file_bytes) + " bytes, after event " + std::to_string(scan.events) +
         ", are not a whole event and were not played";
}

std::string log_path_of_url(const std::string& url) {
  const std::string scheme = "file://";
  if (url.rfind(scheme, 0) != 0) return "";
  const std::string rest = url.substr(scheme.size());
  return rest.substr(0, rest.find('?'));
}

}  // namespace nudge::bus
