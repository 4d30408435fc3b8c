// nudge-report RUN_DIR: writes RUN_DIR/report.html, the run's report (common/viewer/report.hpp),
// with the supervisor's timeline read from the run's LCM log (RUN_DIR/<run>.lcmlog, or --log).
// The demo calls it at the end of every run. The file is written atomically.
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <iostream>

#include "nudge/atomic_file.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/decode.hpp"
#include "nudge/flags.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/viewer/report.hpp"

using namespace nudge;
namespace fs = std::filesystem;

namespace {

// The supervisor's transitions in the log (its 1 Hz repeats folded by StateTimeline).
std::vector<viewer::StateEntry> states_in_log(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot read the run's LCM log " + path);
  viewer::StateTimeline timeline(100000);
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != bus::channel::SUPERVISOR_STATE) continue;
    supervisor_state_t msg;
    if (!bus::decode_message(e->data, static_cast<int>(e->datalen), &msg).empty()) continue;  // malformed: skipped
    viewer::StateEntry entry;
    entry.utime = msg.utime;
    entry.run_id = msg.run_id;
    entry.state = msg.state_name;
    entry.attempt = msg.attempt;
    entry.reason = msg.reason;
    entry.segmented = msg.segmented;
    entry.failed_attempts = msg.failed_attempts;
    timeline.observe(entry);
  }
  return {timeline.entries().begin(), timeline.entries().end()};
}

}  // namespace

int main(int argc, char** argv) {
  Flags flags("nudge-report", "Writes RUN_DIR/report.html: a run's states, attempts, pictures and figures.");
  std::string log_path;
  flags.set_positional("RUN_DIR", "a run folder the supervisor wrote (summary.json, attempt_NN/)");
  flags.add_string("log", &log_path, "the run's LCM log (default: RUN_DIR/<RUN_DIR's name>.lcmlog)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (flags.positional().size() != 1) throw FlagError("give exactly one RUN_DIR");
  } catch (const FlagError& e) {
    std::cerr << "nudge-report: " << e.what() << "\n";
    return 2;
  }
  try {
    const fs::path dir = flags.positional()[0];
    if (log_path.empty()) log_path = (dir / (fs::absolute(dir).lexically_normal().filename().string() + ".lcmlog")).string();
    std::vector<viewer::StateEntry> states;
    if (fs::exists(log_path)) states = states_in_log(log_path);
    else std::cerr << "nudge-report: no log " << log_path << ": the report has no timeline\n";
    const std::string out = (dir / "report.html").string();
    write_file_atomically(out, viewer::render_run_report(dir.string(), states));
    std::cout << out << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "nudge-report: " << e.what() << "\n";
    return 1;
  }
}
