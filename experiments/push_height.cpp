// How high the nudge's pad should push (issue 10; thesis fig. 6.3: "P1 low beside the object").
// The arm service's own nudge plan (robot::plan_command, the workspace file's arm) is played on
// the simulated PUMA 260 in one process (sim::play_motion), the pad on its flange, against one
// object at a time: every kind of the object library, empty or part filled, at placements, yaws,
// push directions and survey errors drawn from a seed fixed in advance. Each placement is pushed
// from the same start at every push height, so the heights are compared on the same pushes.
//   nudge-exp-push-height [--workspace config/workspace.yaml] [--seed 9301] [--placements 24]
//                         [--heights 10,20,30,40,50] [--name push_height]
// Writes docs/results/NAME.{json,md}: per push height the share of pushes that left the object
// fallen (tilted past 30 deg), and how far the upright ones slid.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/robot/command_planner.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/workspace.hpp"
#include "nudge/sim/arm_motion.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/scene.hpp"
#include "nudge/sim/world.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace robot = nudge::robot;
namespace sim = nudge::sim;

namespace {

constexpr double kFallenTilt = 30.0 * M_PI / 180.0;
constexpr double kBarelyMoved = 0.005;  // m: a slide the motion segmentation may not see

// One object, where it stands, and the push aimed at it.
struct Trial {
  std::string kind;
  Eigen::Vector2d position;
  double yaw = 0, fill = 0;
  Eigen::Vector2d aim_error;  // the survey's error: the push is aimed here off the axis
  Eigen::Vector2d direction;
};

struct Outcome {
  bool planned = false;
  std::string refusal;
  double max_tilt = 0, final_tilt = 0, moved = 0;
  bool fallen() const { return planned && final_tilt > kFallenTilt; }
};

// Placements in the arm's reach, in front of the cameras, as the scene sets place objects; a
// push across the right camera's view (the thesis' direction), one of its two senses.
std::vector<Trial> draw_trials(int placements, unsigned seed, const Eigen::Vector3d& right_camera,
                               double aim_error) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0.20, 0.32), y(-0.10, 0.10), unit(0, 1);
  std::vector<Trial> trials;
  for (const std::string& kind : sim::object_kinds()) {
    for (int i = 0; i < placements; ++i) {
      Trial t;
      t.kind = kind;
      t.position = {x(rng), y(rng)};
      t.yaw = 2 * M_PI * unit(rng);
      t.fill = unit(rng) < 1.0 / 3 ? 0.0 : 0.3 + 0.5 * unit(rng);
      const double r = aim_error * std::sqrt(unit(rng)), a = 2 * M_PI * unit(rng);
      t.aim_error = {r * std::cos(a), r * std::sin(a)};
      const auto across = robot::directions_across_view(right_camera, Eigen::Vector3d(t.position.x(), t.position.y(), 0));
      t.direction = across[unit(rng) < 0.5 ? 0 : 1].head<2>();
      trials.push_back(t);
    }
  }
  return trials;
}

sim::Scene scene_of(const Trial& t) {
  sim::Scene scene = sim::default_scene();
  scene.source = "push_height:" + t.kind;
  scene.arm.present = true;
  sim::ObjectSpec o;
  o.kind = t.kind;
  o.position = t.position;
  o.yaw = t.yaw;
  o.fill = t.kind == "marker" ? 0.0 : t.fill;  // a marker has no liquid space
  scene.objects.push_back(o);
  return scene;
}

Outcome push_once(const Trial& t, const robot::PlannerConfig& config, double height) {
  sim::World world(scene_of(t));
  world.mount_tools_on_arm(config.model.tool.translation().norm());
  world.step_for(0.3);
  Outcome out;
  // The arm goes home first, as the supervisor sends it, then nudges from there.
  robot::Command home;
  home.kind = robot::CommandKind::Home;
  const robot::MotionPlan to_home = sim::plan_and_play(world, config, home);
  if (!to_home.ok()) throw std::runtime_error("the move home was refused: " + to_home.reason);
  world.step_for(0.3);
  const sim::ObjectState before = world.object(0);

  robot::Command nudge;
  nudge.kind = robot::CommandKind::Nudge;
  nudge.target_position = Eigen::Vector3d(t.position.x() + t.aim_error.x(), t.position.y() + t.aim_error.y(), 0);
  nudge.direction = Eigen::Vector3d(t.direction.x(), t.direction.y(), 0);
  nudge.height = height;
  nudge.object_height = sim::make_object(t.kind).height;
  sim::MotionPlayback playback;
  playback.each_period = [&](const sim::World& w) { out.max_tilt = std::max(out.max_tilt, w.object(0).tilt()); };
  const robot::MotionPlan plan = sim::plan_and_play(world, config, nudge, playback);
  if (!plan.ok()) {
    out.refusal = plan.reason;
    return out;
  }
  out.planned = true;
  world.step_for(1.5);
  const sim::ObjectState after = world.object(0);
  out.final_tilt = after.tilt();
  out.max_tilt = std::max(out.max_tilt, out.final_tilt);
  out.moved = (after.position - before.position).head<2>().norm();
  return out;
}

struct Tally {
  int pushes = 0, refused = 0, fallen = 0, barely_moved = 0;
  std::vector<double> moved_mm, max_tilt_deg;  // of the upright ones
  void add(const Outcome& o) {
    ++pushes;
    if (!o.planned) {
      ++refused;
      return;
    }
    if (o.fallen()) {
      ++fallen;
      return;
    }
    if (o.moved < kBarelyMoved) ++barely_moved;
    moved_mm.push_back(1000 * o.moved);
    max_tilt_deg.push_back(o.max_tilt * 180 / M_PI);
  }
  int planned() const { return pushes - refused; }
  double fallen_share() const { return planned() ? static_cast<double>(fallen) / planned() : 0.0; }
};

std::string mm(double metres) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(0) << 1000 * metres;
  return s.str();
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  std::string workspace_path = "config/workspace.yaml", name = "push_height";
  int seed = 9301, placements = 24;
  double aim_error = 0.010;
  std::string heights_mm = "10,20,30,40,50";
  Flags flags("nudge-exp-push-height",
              "The arm's nudge played on the simulated PUMA at several push heights: how often the object falls.");
  flags.add_string("workspace", &workspace_path, "the arm's workspace file");
  flags.add_int("seed", &seed, "seed of the placements (9301: the reported set, fixed in advance)");
  flags.add_int("placements", &placements, "placements per object kind");
  flags.add_double("aim-error", &aim_error, "the survey's error: pushes are aimed up to this far off the axis, m");
  flags.add_string("heights", &heights_mm, "push heights to compare (tool point above the table), mm, comma-separated");
  flags.add_string("name", &name, "result name");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (placements < 1) throw std::invalid_argument("--placements must be at least 1");
    std::vector<double> heights;
    for (const std::string& h : split_list(heights_mm)) heights.push_back(0.001 * parse_double(h, "--heights"));
    if (heights.empty()) throw std::invalid_argument("--heights must name at least one height");
    if (!(aim_error >= 0 && aim_error < 0.05)) throw std::invalid_argument("--aim-error must lie in [0, 0.05) m");
    robot::PlannerConfig config = robot::planner_config(robot::load_workspace(workspace_path));
    for (double h : heights) {
      robot::NudgeParams p = config.nudge;
      p.push_height = h;
      robot::validate(p);  // names a height the planner cannot take
    }
    const sim::Scene reference = sim::default_scene();
    const Eigen::Vector3d right_camera = sim::World(reference).camera(1).centre();
    const std::vector<Trial> trials = draw_trials(placements, static_cast<unsigned>(seed), right_camera, aim_error);

    Progress progress("nudge-exp-push-height", static_cast<int>(trials.size()));
    std::map<double, Tally> by_height;
    std::map<std::pair<std::string, double>, Tally> by_kind;
    int fallen_only_higher = 0, fallen_only_lower = 0;  // paired: lowest height against the highest
    for (const Trial& t : trials) {
      progress.step(t.kind + " at (" + mm(t.position.x()) + ", " + mm(t.position.y()) + ") mm");
      std::vector<Outcome> outcomes;
      for (double h : heights) {
        outcomes.push_back(push_once(t, config, h));
        by_height[h].add(outcomes.back());
        by_kind[{t.kind, h}].add(outcomes.back());
      }
      if (outcomes.front().planned && outcomes.back().planned) {
        fallen_only_lower += outcomes.front().fallen() && !outcomes.back().fallen();
        fallen_only_higher += !outcomes.front().fallen() && outcomes.back().fallen();
      }
    }
    progress.finish();

    std::ostringstream md;
    md << "# Push height: how often the nudge knocks the object over\n\n"
       << "`nudge-exp-push-height --seed " << seed << " --placements " << placements << " --aim-error " << aim_error
       << "` (" << today() << "; " << machine_description() << ").\n\n"
       << "The arm service's nudge (robot::plan_command with the workspace file's arm) played on the simulated "
          "PUMA 260, the pad on its flange: each of the " << sim::object_kinds().size() << " object kinds at "
       << placements << " placements (x 200-320 mm, y -100-100 mm, any yaw; a third empty, the rest 30-80 % "
          "filled), pushed across the right camera's view, aimed up to " << mm(aim_error)
       << " mm off the axis (the survey's error). Every placement is pushed at every height from the same start. "
          "Fallen: tilted more than 30 deg when settled. Slide: of the upright ones.\n\n"
       << "| push height (mm) | pushes | refused | fallen | fallen share | median slide (mm) | slid < 5 mm | "
          "median max tilt (deg) |\n|---|---|---|---|---|---|---|---|\n";
    JsonWriter json;
    json.begin_object().field("seed", seed).field("placements_per_kind", placements).field("aim_error_m", aim_error);
    json.key("by_height").begin_array();
    for (const auto& [h, tally] : by_height) {
      md << "| " << mm(h) << " | " << tally.pushes << " | " << tally.refused << " | " << tally.fallen << " | "
         << fixed(tally.fallen_share(), 3) << " | " << fixed(median(tally.moved_mm), 1) << " | "
         << tally.barely_moved << " | " << fixed(median(tally.max_tilt_deg), 1) << " |\n";
      json.begin_object().field("push_height_m", h).field("pushes", tally.pushes).field("refused", tally.refused)
          .field("fallen", tally.fallen).field("fallen_share", tally.fallen_share())
          .field("median_slide_mm", median(tally.moved_mm)).field("slid_under_5mm", tally.barely_moved).end_object();
    }
    json.end_array();
    md << "\nPaired, the same placements: fallen at " << mm(heights.front()) << " mm but not at "
       << mm(heights.back()) << " mm: " << fallen_only_lower << "; the other way round: " << fallen_only_higher
       << ".\n\n## Fallen by kind\n\n| kind |";
    for (double h : heights) md << " " << mm(h) << " mm |";
    md << "\n|---|";
    for (size_t i = 0; i < heights.size(); ++i) md << "---|";
    md << "\n";
    json.key("fallen_by_kind").begin_object();
    for (const std::string& kind : sim::object_kinds()) {
      md << "| " << kind << " |";
      json.key(kind).begin_array();
      for (double h : heights) {
        const Tally& tally = by_kind[{kind, h}];
        md << " " << tally.fallen << "/" << tally.planned() << " |";
        json.value(tally.fallen);
      }
      json.end_array();
      md << "\n";
    }
    json.end_object();
    json.field("fallen_lower_not_higher", fallen_only_lower).field("fallen_higher_not_lower", fallen_only_higher);
    json.end_object();
    write_result(name + ".md", md.str());
    write_result(name + ".json", json.str() + "\n");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-push-height: " << e.what() << "\n";
    return 1;
  }
}
