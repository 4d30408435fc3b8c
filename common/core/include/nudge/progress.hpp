#pragma once
// Progress of a long job (an experiment, a calibration, a demo step) for the person waiting:
//   nudge-exp-clutter: 40 steps
//   [12/40] scene s03 … 34 s left          (one line, rewritten in place on a terminal)
//   nudge-exp-clutter: done 40/40 in 1 m 12 s — 38 segmented
// On a terminal every step rewrites the status line; otherwise (CI, a log file) only the start
// and end lines are written, so that logs stay short. Written to stderr: stdout stays free for
// a tool's machine-readable output.
#include <chrono>
#include <functional>
#include <ostream>
#include <string>

namespace nudge {

class Progress {
 public:
  using Clock = std::function<double()>;  // seconds, monotonic

  // `total` steps (0: unknown). `interactive` defaults to "stderr is a terminal".
  Progress(std::string job, int total);
  Progress(std::string job, int total, std::ostream& out, bool interactive, Clock clock);
  ~Progress();  // an unfinished job still ends its line (e.g. after an exception)
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Starts the next step, named `item` (e.g. "scene s03"): counts the previous one as done.
  void step(const std::string& item);
  // A line of detail (e.g. a step's result) above the status line: the status is redrawn under it.
  void note(const std::string& line);
  // Blanks the status line on a terminal, before something else writes to stderr (a log line);
  // the next step() draws it again.
  void clear_status();
  // The one-line summary; counts the last step as done. Later calls do nothing.
  void finish(const std::string& summary = "");

  int done() const { return done_; }
  double elapsed_s() const;
  // Seconds left at the mean pace of the steps done so far; negative when unknown.
  double remaining_s() const;

  // "850 ms", "34 s", "1 m 12 s", "2 h 05 m".
  static std::string format_duration(double seconds);

 private:
  void write_status(const std::string& item);

  std::string job_;
  int total_;
  std::ostream& out_;
  bool interactive_;
  Clock clock_;
  double start_s_;
  int done_ = 0;
  bool started_step_ = false;
  bool finished_ = false;
  size_t status_width_ = 0;  // the status line's length, to blank it when it shrinks
  std::string item_;         // the current step's name, to redraw its status
};

}  // namespace nudge
