#include "nudge/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace nudge {
namespace {
double monotonic_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

Progress::Progress(std::string job, int total)
    : Progress(std::move(job), total, std::cerr, isatty(STDERR_FILENO) == 1, monotonic_seconds) {}

Progress::Progress(std::string job, int total, std::ostream& out, bool interactive, Clock clock)
    : job_(std::move(job)),
      total_(total),
      out_(out),
      interactive_(interactive),
      clock_(std::move(clock)),
      start_s_(clock_()) {
  out_ << job_ << ": " << (total_ > 0 ? std::to_string(total_) + " steps" : "started") << "\n";
  out_.flush();
}

Progress::~Progress() {
  if (!finished_) finish("stopped early");
}

double Progress::elapsed_s() const { return clock_() - start_s_; }

double Progress::remaining_s() const {
  if (total_ <= 0 || done_ <= 0) return -1;
  return elapsed_s() / done_ * (total_ - done_);
}

void Progress::step(const std::string& item) {
  if (finished_) return;
  if (started_step_) ++done_;
  started_step_ = true;
  item_ = item;
  if (interactive_) write_status(item);
}

void Progress::note(const std::string& line) {
  if (interactive_) clear_status();
  out_ << line << "\n";
  if (interactive_ && started_step_ && !finished_) write_status(item_);
  out_.flush();
}

void Progress::clear_status() {
  if (status_width_ > 0) out_ << "\r" << std::string(status_width_, ' ') << "\r";
  status_width_ = 0;
}

void Progress::write_status(const std::string& item) {
  std::ostringstream line;
  line << "[" << (done_ + 1);
  if (total_ > 0) line << "/" << total_;
  line << "] " << item;
  const double left = remaining_s();
  if (left >= 0) line << " … " << format_duration(left) << " left";
  std::string text = line.str();
  const size_t width = text.size();
  // Blank what is left of a longer previous status, so that no stale characters remain.
  if (width < status_width_) text += std::string(status_width_ - width, ' ');
  status_width_ = width;
  out_ << "\r" << text;
  out_.flush();
}

void Progress::finish(const std::string& summary) {
  if (finished_) return;
  finished_ = true;
  if (started_step_) ++done_;
  if (interactive_) clear_status();
  out_ << job_ << ": done ";
  if (total_ > 0) out_ << done_ << "/" << total_ << " ";
  out_ << "in " << format_duration(elapsed_s());
  if (!summary.empty()) out_ << " — " << summary;
  out_ << "\n";
  out_.flush();
}

std::string Progress::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char text[32];
  if (seconds < 1) {
    std::snprintf(text, sizeof text, "%d ms", static_cast<int>(std::lround(seconds * 1000)));
  } else if (seconds < 60) {
    std::snprintf(text, sizeof text, "%d s", static_cast<int>(std::lround(seconds)));
  } else if (seconds < 3600) {
    const long s = std::lround(seconds);
    std::snprintf(text, sizeof text, "%ld m %02ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60);
    std::snprintf(text, sizeof text, "%ld h %02ld m", m / 60, m % 60);
  }
  return text;
}

}  // namespace nudge
