#include "soak_probe.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace nudge::experiments::soak {

namespace {

std::optional<std::string> read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::optional<double> parse_vm_rss_mb(const std::string& status_text) {
  std::istringstream in(status_text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    double kb = 0;
    if (fields >> kb) return kb / 1024.0;
  }
  return std::nullopt;
}

std::optional<int64_t> parse_cpu_ticks(const std::string& stat_text) {
  const size_t close = stat_text.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream in(stat_text.substr(close + 1));
  // After the command: state(3) ppid pgrp session tty_nr tpgid flags minflt cminflt majflt
  // cmajflt utime(14) stime(15).
  std::string field;
  int64_t utime = 0, stime = 0;
  for (int i = 3; i <= 13; ++i)
    if (!(in >> field)) return std::nullopt;
  if (!(in >> utime >> stime)) return std::nullopt;
  return utime + stime;
}

std::optional<ProcessSample> sample_process(int pid) {
  const std::string dir = "/proc/" + std::to_string(pid);
  const auto status = read_text(dir + "/status");
  const auto stat = read_text(dir + "/stat");
  if (!status || !stat) return std::nullopt;
  const auto rss = parse_vm_rss_mb(*status);
  const auto ticks = parse_cpu_ticks(*stat);
  if (!rss || !ticks) return std::nullopt;  // a zombie has no VmRSS
  return ProcessSample{*rss, static_cast<double>(*ticks) / static_cast<double>(sysconf(_SC_CLK_TCK))};
}

std::map<uint64_t, int64_t> parse_udp_drops(const std::string& proc_net_udp_text) {
  std::map<uint64_t, int64_t> drops;
  std::istringstream in(proc_net_udp_text);
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    // sl local rem st tx:rx tr:tm retrnsmt uid timeout inode ref pointer drops
    std::istringstream fields(line);
    std::vector<std::string> f;
    for (std::string s; fields >> s;) f.push_back(s);
    if (f.size() < 13) continue;
    try {
      drops[std::stoull(f[9])] += std::stoll(f[12]);
    } catch (const std::exception&) {
      continue;  // not a socket line
    }
  }
  return drops;
}

std::vector<uint64_t> socket_inodes(int pid) {
  std::vector<uint64_t> inodes;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
    std::error_code link_ec;
    const std::string target = std::filesystem::read_symlink(entry.path(), link_ec).string();
    if (link_ec || target.rfind("socket:[", 0) != 0) continue;
    inodes.push_back(std::stoull(target.substr(8)));
  }
  return inodes;
}

int64_t socket_drops(int pid) {
  std::map<uint64_t, int64_t> drops;
  for (const char* table : {"/proc/net/udp", "/proc/net/udp6"})
    if (const auto text = read_text(table))
      for (const auto& [inode, n] : parse_udp_drops(*text)) drops[inode] += n;
  int64_t total = 0;
  for (uint64_t inode : socket_inodes(pid)) {
    const auto it = drops.find(inode);
    if (it != drops.end()) total += it->second;
  }
  return total;
}

double quantile(std::vector<double> samples, double q) {
  if (samples.empty()) return std::nan("");
  std::sort(samples.begin(), samples.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(samples.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, samples.size() - 1);
  return samples[lo] + (pos - static_cast<double>(lo)) * (samples[hi] - samples[lo]);
}

}  // namespace nudge::experiments::soak
