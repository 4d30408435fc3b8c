// Can the simulated lab run in real time? Stereo 640x480 at 25 Hz (the thesis' camera rate), shadows
// off: per 40 ms of simulated time, the world steps its physics (20 steps of 2 ms) and the camera's
// sim backend sets the published poses and renders both cameras. The realtime factor achievable is
// 40 ms over the time that takes on one core (the world and the camera are separate processes, so
// on two free cores the slower of the two sets the pace: that factor is reported too).
//   nudge-exp-sim-realtime [--seconds 4] [--scenes a.yaml,b.yaml]
// Writes docs/results/sim_realtime.{json,md}.
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/timing.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;

namespace {

constexpr double kFramePeriod = 0.04;  // s: 25 Hz

struct SceneTiming {
  std::string scene;
  int objects = 0, frames = 0;
  double physics_ms_per_frame = 0;  // per 40 ms of simulated time
  double sync_ms_per_frame = 0;     // the camera teleporting objects and pusher to the state's poses
  double render_ms_per_frame = 0;   // one camera image (median over both cameras and all frames)
  double physics_steps_per_s = 0;
  double one_core_factor() const {
    return 1e3 * kFramePeriod / (physics_ms_per_frame + sync_ms_per_frame + 2 * render_ms_per_frame);
  }
  double two_core_factor() const {
    return 1e3 * kFramePeriod / std::max(physics_ms_per_frame, sync_ms_per_frame + 2 * render_ms_per_frame);
  }
};

SceneTiming measure(const std::string& path, double seconds) {
  sim::Scene scene = sim::load_scene(path);
  scene.render.shadows = false;
  scene.render.reflections = false;
  sim::World physics(scene);  // the world service's
  sim::World camera(scene);   // the camera's, rendering only
  camera.render(0);           // makes the OpenGL context (a one-off ~0.1 s, not a per-frame cost)
  // A cup-sized push through the workspace, so that contacts are part of the physics cost.
  physics.set_pusher({0.25, -0.25, 0.03}, M_PI / 2);
  SceneTiming t;
  t.scene = path.substr(path.find_last_of('/') + 1);
  t.objects = physics.num_objects();
  const int steps = static_cast<int>(std::lround(kFramePeriod / physics.timestep()));
  std::vector<double> physics_ms, sync_ms, render_ms;
  for (double time = 0; time < seconds - 1e-9; time += kFramePeriod) {
    const double y = -0.25 + 0.5 * time / seconds;  // the pad sweeps across the workspace at ~0.1 m/s
    Stopwatch w;
    for (int s = 0; s < steps; ++s) {
      physics.set_pusher({0.25, y, 0.03}, M_PI / 2);
      physics.step();
    }
    physics_ms.push_back(w.lap_ms());
    sim::apply_poses(camera, sim::snapshot_poses(physics, M_PI / 2));
    sync_ms.push_back(w.lap_ms());
    for (int c = 0; c < 2; ++c) {
      camera.render(c);
      render_ms.push_back(w.lap_ms());
    }
    ++t.frames;
  }
  t.physics_ms_per_frame = median(physics_ms);
  t.sync_ms_per_frame = median(sync_ms);
  t.render_ms_per_frame = median(render_ms);
  t.physics_steps_per_s = 1e3 * steps / mean(physics_ms);
  return t;
}

void write_results(const std::vector<SceneTiming>& results, double seconds) {
  JsonWriter j(4);
  j.begin_object();
  j.field("machine", machine_description()).field("date", today());
  j.field("image", "640x480 stereo, shadows off").field("frame_rate_hz", 1.0 / kFramePeriod);
  j.field("seconds_simulated", seconds);
  // Headline figures: the most demanding scene (the last, most objects), world and camera on one core.
  const SceneTiming& worst = results.back();
  j.field("headline_scene", worst.scene).field("realtime_factor", worst.one_core_factor());
  j.field("render_ms_per_frame", worst.render_ms_per_frame).field("physics_steps_per_s", worst.physics_steps_per_s);
  j.key("scenes").begin_array();
  for (const auto& t : results) {
    j.begin_object();
    j.field("scene", t.scene).field("objects", t.objects).field("frames", t.frames);
    j.field("physics_ms_per_frame", t.physics_ms_per_frame).field("sync_ms_per_frame", t.sync_ms_per_frame);
    j.field("render_ms_per_frame", t.render_ms_per_frame).field("physics_steps_per_s", t.physics_steps_per_s);
    j.field("realtime_factor_one_core", t.one_core_factor()).field("realtime_factor_two_cores", t.two_core_factor());
    j.end_object();
  }
  j.end_array();
  j.end_object();
  write_result("sim_realtime.json", j.str() + "\n");

  std::ostringstream md;
  md << "# Simulation in real time\n\n"
     << "Stereo 640x480 at 25 Hz, shadows and reflections off; per 40 ms of simulated time the world steps "
     << "its physics (2 ms steps, a pusher sweeping through the workspace) and the camera's sim backend "
     << "teleports its copy of the scene to the new poses and renders both cameras (medians over " << seconds
     << " s). Realtime factor = 40 ms / (physics + pose sync + 2 renders) on one core; the world and the "
     << "camera are separate processes, so with two free cores the slower one sets the pace.\n\n"
     << "Machine: " << machine_description() << ", " << today() << ". `nudge-exp-sim-realtime`.\n\n"
     << "| scene | objects | physics ms / 40 ms | pose sync ms | render ms / image | physics steps/s | "
        "realtime factor, 1 core | 2 cores |\n|---|---|---|---|---|---|---|---|\n";
  md.precision(3);
  for (const auto& t : results) {
    md << "| `" << t.scene << "` | " << t.objects << " | " << t.physics_ms_per_frame << " | " << t.sync_ms_per_frame
       << " | " << t.render_ms_per_frame << " | " << std::lround(t.physics_steps_per_s) << " | "
       << t.one_core_factor() << " | " << t.two_core_factor() << " |\n";
  }
  write_result("sim_realtime.md", md.str());
}

}  // namespace

int main(int argc, char** argv) {
  Flags flags("nudge-exp-sim-realtime", "Realtime factor of the simulated lab: physics + stereo rendering at 25 Hz.");
  double seconds = 4.0;
  std::string scenes = std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/single_cup.yaml," + NUDGE_SOURCE_DIR +
                       "/common/sim/scenes/three_objects.yaml," + NUDGE_SOURCE_DIR +
                       "/common/sim/scenes/arm_three_objects.yaml," + NUDGE_SOURCE_DIR +
                       "/common/sim/scenes/cluttered.yaml";
  flags.add_double("seconds", &seconds, "simulated seconds per scene");
  flags.add_string("scenes", &scenes, "comma-separated scene files");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (!(seconds >= kFramePeriod)) throw FlagError("--seconds must be >= 0.04");
    std::vector<SceneTiming> results;
    std::vector<std::string> paths;
    std::stringstream list(scenes);
    for (std::string path; std::getline(list, path, ',');)
      if (!path.empty()) paths.push_back(path);
    nudge::Progress progress("nudge-exp-sim-realtime", static_cast<int>(paths.size()));
    for (const std::string& path : paths) {
      progress.step(path.substr(path.rfind('/') + 1));
      results.push_back(measure(path, seconds));
      const auto& t = results.back();
      std::ostringstream line;
      line << t.scene << ": physics " << t.physics_ms_per_frame << " ms, sync " << t.sync_ms_per_frame
           << " ms, render " << t.render_ms_per_frame << " ms per image -> realtime factor " << t.one_core_factor()
           << " (1 core), " << t.two_core_factor() << " (2 cores)";
      progress.note(line.str());
    }
    progress.clear_status();  // the result files' "wrote" lines follow on stderr
    write_results(results, seconds);
    std::ostringstream summary;
    summary << results.size() << " scenes, " << seconds << " simulated s each";
    progress.finish(summary.str());
  } catch (const FlagError& e) {
    std::cerr << "nudge-exp-sim-realtime: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-sim-realtime: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
