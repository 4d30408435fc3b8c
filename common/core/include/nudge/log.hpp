#pragma once
// Consistent, line-oriented logging for services and tools:
//   2026-11-22T11:30:00.123Z I symmetry: message
// Written to stderr so that stdout stays free for a tool's machine-readable output.
#include <sstream>
#include <string>

namespace nudge::log {

enum class Level { Debug = 0, Info = 1, Warn = 2, Error = 3 };

void set_component(const std::string& name);  // e.g. the service name
void set_level(Level level);
Level level();
void write(Level level, const std::string& message);

// Usage: nudge::log::info() << "published " << n << " lines";
class Line {
 public:
  explicit Line(Level level) : level_(level) {}
  Line(const Line&) = delete;
  ~Line() { write(level_, stream_.str()); }
  template <typename T>
  Line& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  Level level_;
  std::ostringstream stream_;
};

inline Line debug() { return Line(Level::Debug); }
inline Line info() { return Line(Level::Info); }
inline Line warn() { return Line(Level::Warn); }
inline Line error() { return Line(Level::Error); }

}  // namespace nudge::log
