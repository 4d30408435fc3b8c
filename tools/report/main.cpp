// nudge-report RUN_DIR: writes RUN_DIR/report.html, the run's report (common/viewer/report.hpp),
// with the supervisor's timeline read from the run's LCM log (RUN_DIR/<run>.lcmlog, or --log) and,
// in simulation (--scene), the IoU of every segmentation against the simulator's truth.
// The demo calls it at the end of every run. The file is written atomically.
#include <filesystem>
#include <iostream>

#include "nudge/atomic_file.hpp"
#include "nudge/bus/viewer_convert.hpp"
#include "nudge/flags.hpp"
#include "nudge/viewer/report.hpp"
#ifdef NUDGE_REPORT_SIM
#include "sim_scores.hpp"
#endif

using namespace nudge;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  Flags flags("nudge-report", "Writes RUN_DIR/report.html: a run's states, attempts, pictures and figures.");
  std::string log_path, scene_file;
  flags.set_positional("RUN_DIR", "a run folder the supervisor wrote (summary.json, attempt_NN/)");
  flags.add_string("log", &log_path, "the run's LCM log (default: RUN_DIR/<RUN_DIR's name>.lcmlog)");
  flags.add_string("scene", &scene_file,
                   "in simulation: the scene file the run's world loaded; adds the IoU per object");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (flags.positional().size() != 1) throw FlagError("give exactly one RUN_DIR");
#ifndef NUDGE_REPORT_SIM
    if (!scene_file.empty()) throw FlagError("--scene: this build has no simulator (NUDGE_EXCLUDE=sim)");
#endif
  } catch (const FlagError& e) {
    std::cerr << "nudge-report: " << e.what() << "\n";
    return 2;
  }
  try {
    const fs::path dir = flags.positional()[0];
    if (log_path.empty()) log_path = (dir / (fs::absolute(dir).lexically_normal().filename().string() + ".lcmlog")).string();
    std::vector<viewer::StateEntry> states;
    std::vector<viewer::SimulationScore> scores;
    if (fs::exists(log_path)) {
      states = bus::supervisor_states_in_log(log_path);
#ifdef NUDGE_REPORT_SIM
      if (!scene_file.empty()) scores = report::simulation_scores(log_path, scene_file);
#endif
    } else {
      std::cerr << "nudge-report: no log " << log_path << ": the report has no timeline"
                << (scene_file.empty() ? "" : " and no IoU") << "\n";
    }
    const std::string out = (dir / "report.html").string();
    write_file_atomically(out, viewer::render_run_report(dir.string(), states, scores));
    std::cout << out << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "nudge-report: " << e.what() << "\n";
    return 1;
  }
}
