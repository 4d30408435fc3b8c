#include "nudge/log.hpp"

#include <sys/time.h>

#include <atomic>
#include <cstdio>
#include <ctime>
#include <mutex>

namespace nudge::log {
namespace {
std::mutex g_mutex;
std::string g_component = "nudge";
std::atomic<int> g_level{static_cast<int>(Level::Info)};

char level_letter(Level level) {
  switch (level) {
    case Level::Debug: return 'D';
    case Level::Info: return 'I';
    case Level::Warn: return 'W';
    case Level::Error: return 'E';
  }
  return '?';
}
}  // namespace

void set_component(const std::string& name) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_component = name;
}

void set_level(Level level) { g_level = static_cast<int>(level); }
Level level() { return static_cast<Level>(g_level.load()); }

void write(Level lvl, const std::string& message) {
  if (static_cast<int>(lvl) < g_level.load()) return;
  timeval tv{};
  gettimeofday(&tv, nullptr);
  std::tm utc{};
  gmtime_r(&tv.tv_sec, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &utc);
  std::lock_guard<std::mutex> lock(g_mutex);
  std::fprintf(stderr, "%s.%03dZ %c %s: %s\n", stamp, static_cast<int>(tv.tv_usec / 1000),
               level_letter(lvl), g_component.c_str(), message.c_str());
  std::fflush(stderr);
}

}  // namespace nudge::log
