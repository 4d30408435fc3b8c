// nudge::log on spdlog: the same line format as before spdlog (scripts and people read it),
//   2026-11-22T11:30:00.123Z I symmetry: message
// with spdlog's thread-safe stderr sink doing the writing and the UTC time stamps.
#include "nudge/log.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <memory>
#include <mutex>

namespace nudge::log {
namespace {
std::mutex g_component_mutex;
std::string g_component = "nudge";
std::atomic<int> g_level{static_cast<int>(Level::Info)};

spdlog::level::level_enum spdlog_level(Level level) {
  switch (level) {
    case Level::Debug: return spdlog::level::debug;
    case Level::Info: return spdlog::level::info;
    case Level::Warn: return spdlog::level::warn;
    case Level::Error: return spdlog::level::err;
  }
  return spdlog::level::info;
}

// One logger for the process, made on first use (no static-initialisation order to worry about)
// and never destroyed, so that a thread or a static destructor logging while the process exits
// still finds it. Unregistered: spdlog's global registry is left to whoever else links spdlog.
spdlog::logger& logger() {
  static spdlog::logger* const instance = [] {
    auto* made = new spdlog::logger("nudge", std::make_shared<spdlog::sinks::stderr_sink_mt>());
    // %L: spdlog's one-letter level (D, I, W, E); the component goes in with the message.
    made->set_formatter(std::make_unique<spdlog::pattern_formatter>("%Y-%m-%dT%H:%M:%S.%eZ %L %v",
                                                                    spdlog::pattern_time_type::utc));
    made->set_level(spdlog::level::trace);  // nudge::log filters by g_level
    made->flush_on(spdlog::level::trace);   // every line at once: services are watched live
    return made;
  }();
  return *instance;
}
}  // namespace

void set_component(const std::string& name) {
  std::lock_guard<std::mutex> lock(g_component_mutex);
  g_component = name;
}

void set_level(Level level) { g_level = static_cast<int>(level); }
Level level() { return static_cast<Level>(g_level.load()); }

void write(Level lvl, const std::string& message) {
  if (static_cast<int>(lvl) < g_level.load()) return;
  std::string component;
  {
    std::lock_guard<std::mutex> lock(g_component_mutex);
    component = g_component;
  }
  logger().log(spdlog_level(lvl), "{}: {}", component, message);
}

}  // namespace nudge::log
