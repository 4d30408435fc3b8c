#pragma once
// What the soak recorder (nudge-exp-soak) measures outside LCM: a process's memory and CPU time
// and its UDP sockets' drop counters, read from /proc; percentiles of latency samples.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace nudge::experiments::soak {

struct ProcessSample {
  double rss_mb = 0;        // VmRSS
  double cpu_seconds = 0;   // user + system time so far
};

// /proc/PID/status and /proc/PID/stat; nothing when the process is gone.
std::optional<ProcessSample> sample_process(int pid);
// VmRSS in MB from the text of /proc/PID/status; nothing when the field is missing.
std::optional<double> parse_vm_rss_mb(const std::string& status_text);
// utime + stime in clock ticks from the text of /proc/PID/stat (the command may hold spaces
// and parentheses: fields are counted after the last ')').
std::optional<int64_t> parse_cpu_ticks(const std::string& stat_text);

// Datagrams the kernel dropped because a socket's receive buffer was full, per socket inode,
// from the text of /proc/net/udp (last column).
std::map<uint64_t, int64_t> parse_udp_drops(const std::string& proc_net_udp_text);
// The socket inodes a process holds open (/proc/PID/fd -> "socket:[INODE]").
std::vector<uint64_t> socket_inodes(int pid);
// Drops summed over the sockets of `pid` (this network namespace's /proc/net/udp).
int64_t socket_drops(int pid);

// The q-quantile (0..1) of the samples, linearly interpolated; NaN when there are none.
double quantile(std::vector<double> samples, double q);

}  // namespace nudge::experiments::soak
