#include "nudge/supervisor/targets.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace nudge::supervisor {

namespace {


Eigen::Vector3d horizontal(const Eigen::Vector3d& v) { return Eigen::Vector3d(v.x(), v.y(), 0.0); }

}  // namespace

std::string millimetres(const Eigen::Vector3d& p) {
  char text[64];
  std::snprintf(text, sizeof text, "(%.0f, %.0f) mm", 1e3 * p.x(), 1e3 * p.y());
  return text;
}

robot::SafetyConfig ArmSetup::safety_config() const {
  robot::SafetyConfig config = safety;
  config.table_z = base.table_z();
  return config;
}

robot::PlannerConfig ArmSetup::planner() const {
  robot::PlannerConfig config;
  config.model = model;
  config.safety = safety_config();
  config.base = base;
  config.nudge = nudge;
  return config;
}

robot::JointVector ArmSetup::home() const {
  const robot::IkResult home = robot::home_configuration(model, safety_config());
  return home.ok() ? home.q : robot::JointVector::Zero();
}


PushConflict push_conflict(const Eigen::Vector3d& target, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& other, const ArmSetup& arm, const TargetParams& params,
                           const std::string& what) {
  const Eigen::Vector3d d = horizontal(direction).normalized();
  const Eigen::Vector3d offset = horizontal(other - target);
  const double along = offset.dot(d);
  const double across = (offset - along * d).norm();
  // The pad: a segment from P1 (start_distance before the axis) to P2 (stop_distance before it).
  const double nearest_along = std::clamp(along, -arm.nudge.start_distance, -arm.nudge.stop_distance);
  const double to_pad = std::hypot(along - nearest_along, across);
  if (to_pad < params.object_radius + params.pad_half_width)
    return {PushConflict::Kind::Pad, "the pad would touch the " + what + " at " + millimetres(other)};
  // The pushed object slides up to `travel` ahead: a band two object radii wide.
  if (along >= 0 && along <= params.travel + 2 * params.object_radius && across < 2 * params.object_radius)
    return {PushConflict::Kind::Slide, "the pushed object may slide into the " + what + " at " + millimetres(other)};
  return {};
}

namespace {

bool near_any(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& places, double radius) {
  return std::any_of(places.begin(), places.end(), [&](const Eigen::Vector3d& e) { return horizontal(e - p).norm() < radius; });
}

struct Obstacle {
  Eigen::Vector3d place;
  const char* what;  // for reasons
};

// The places a push must keep clear of: the other candidates that count as objects, and the
// explored objects standing where no candidate is (their lines left out of the survey).
std::vector<Obstacle> obstacles_to(const Candidate& c, const std::vector<Candidate>& candidates, const History& history,
                                   const TargetParams& params) {
  std::vector<Obstacle> obstacles;
  auto far_from_target = [&](const Eigen::Vector3d& p) { return horizontal(p - c.position).norm() >= params.same_object_radius; };
  auto near_an_obstacle = [&](const Eigen::Vector3d& p) {
    return std::any_of(obstacles.begin(), obstacles.end(),
                       [&](const Obstacle& o) { return horizontal(o.place - p).norm() < params.same_object_radius; });
  };
  for (const Candidate& other : candidates) {
    if (other.index == c.index || near_any(other.position, history.empty, params.explored_radius)) continue;
    if (other.stereo_agreement < params.min_stereo_agreement) continue;
    if (far_from_target(other.position)) obstacles.push_back({other.position, "candidate"});
  }
  for (const Eigen::Vector3d& object : history.standing)
    if (far_from_target(object) && !near_an_obstacle(object)) obstacles.push_back({object, "explored object"});
  return obstacles;
}

// One pass over the candidates in camera order. With `strict`, a push that may touch another
// candidate is refused; otherwise it is taken and noted.
TargetChoice choose_pass(const std::vector<Candidate>& candidates, const std::vector<size_t>& order, const History& history,
                         const Eigen::Vector3d& camera_base, const ArmSetup& arm, const robot::JointVector& seed,
                         const TargetParams& params, bool strict) {
  TargetChoice choice;
  for (size_t i : order) {
    const Candidate& c = candidates[i];
    auto reject = [&](const std::string& reason) { choice.rejected.push_back({c.index, c.position, reason}); };
    if (near_any(c.position, history.explored, params.explored_radius) ||
        near_any(c.position, history.phantoms, params.phantom_radius)) {
      reject("already explored");
      continue;
    }
    if (c.stereo_agreement < params.min_nudge_agreement) {
      reject("not seen upright by both cameras (a stereo mismatch)");
      continue;
    }
    std::string why_not;
    const std::vector<Obstacle> obstacles = obstacles_to(c, candidates, history, params);
    for (const Eigen::Vector3d& direction_base :
         robot::directions_across_view(camera_base, arm.point_to_base(c.position))) {
      const Eigen::Vector3d direction = arm.direction_to_world(direction_base);
      PushConflict conflict;
      for (const Obstacle& other : obstacles) {
        PushConflict found = push_conflict(c.position, direction, other.place, arm, params, other.what);
        if (found.kind == PushConflict::Kind::Pad || (found && !conflict)) conflict = found;
        if (conflict.kind == PushConflict::Kind::Pad) break;
      }
      if (conflict && (strict || conflict.kind == PushConflict::Kind::Pad)) {
        why_not += std::string(why_not.empty() ? "" : "; the other way: ") + conflict.reason;
        continue;
      }
      robot::NudgePlan plan =
          robot::plan_nudge(arm.model, arm.safety_config(), arm.point_to_base(c.position), direction_base, arm.nudge, seed);
      if (!plan.ok()) {
        why_not += std::string(why_not.empty() ? "" : "; the other way: ") + "out of reach: " + plan.reason;
        continue;
      }
      // The whole command as the arm service will plan it from where the arm is (the move to P0
      // included): a target it would refuse is not chosen.
      robot::Command command;
      command.kind = robot::CommandKind::Nudge;
      command.target_position = c.position;
      command.direction = horizontal(direction).normalized();
      const robot::MotionPlan arm_plan = robot::plan_command(arm.planner(), command, seed);
      if (!arm_plan.ok()) {
        why_not += std::string(why_not.empty() ? "" : "; the other way: ") + "the arm would refuse: " + arm_plan.reason;
        continue;
      }
      choice.found = true;
      choice.target = c;
      choice.direction = horizontal(direction).normalized();
      choice.plan = std::move(plan);
      if (conflict) choice.note = "no clear push left: " + conflict.reason;
      return choice;
    }
    reject(why_not);
  }
  return choice;
}

}  // namespace

TargetChoice choose_target(const std::vector<Candidate>& candidates, const History& history, const Eigen::Vector3d& right_camera,
                           const ArmSetup& arm, const robot::JointVector& seed, const TargetParams& params) {
  std::vector<size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool seen_a = candidates[a].stereo_agreement >= params.min_stereo_agreement;
    const bool seen_b = candidates[b].stereo_agreement >= params.min_stereo_agreement;
    if (seen_a != seen_b) return seen_a;
    return (candidates[a].position - right_camera).norm() < (candidates[b].position - right_camera).norm();
  });
  const Eigen::Vector3d camera_base = arm.point_to_base(right_camera);
  TargetChoice strict = choose_pass(candidates, order, history, camera_base, arm, seed, params, true);
  if (strict.found) return strict;
  TargetChoice relaxed = choose_pass(candidates, order, history, camera_base, arm, seed, params, false);
  if (!relaxed.found) return strict;  // the strict pass's reasons say why each was passed over
  // Keep the strict pass's reasons for the candidates passed over before the chosen one.
  relaxed.rejected.clear();
  for (const Rejection& r : strict.rejected)
    if (r.index != relaxed.target.index) relaxed.rejected.push_back(r);
  return relaxed;
}

}  // namespace nudge::supervisor
