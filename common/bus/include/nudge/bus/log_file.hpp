#pragma once
// LCM log files as inputs: what a log holds, and whether it ends in the middle of an event (a
// full disk, a logger killed mid-write, a copy cut short). LCM's own reader stops silently at
// such an end, so a service fed by `--lcm-in file://LOG` and nudge-replay say so instead.
#include <cstdint>
#include <string>

namespace nudge::bus {

struct LogScan {
  int64_t events = 0;                     // whole events
  int64_t first_utime = 0, last_utime = 0;  // their stamps (0 when there are none)
  int64_t whole_bytes = 0;                // where the last whole event ends
  int64_t file_bytes = 0;
  bool truncated() const { return whole_bytes < file_bytes; }
};

// One pass over the log at `path`. Throws std::runtime_error naming the path when it cannot be read.
LogScan scan_log(const std::string& path);

// "LOG ends in the middle of an event: the last 60 of 12345 bytes, after event 41, are not a
// whole event and were not played"; "" when the log is whole.
std::string describe_truncation(const std::string& path, const LogScan& scan);

// The file of an LCM file:// URL ("file://in.lcmlog?speed=0" -> "in.lcmlog"); "" for other URLs.
std::string log_path_of_url(const std::string& url);

}  // namespace nudge::bus
