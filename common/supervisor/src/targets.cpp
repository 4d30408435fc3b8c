#include "nudge/supervisor/targets.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <optional>
#include <string>
#include <utility>
#include <variant>

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
  // The pad sweeps a rectangle: from P1 (start_distance before the axis) to P2 (stop_distance
  // before it), as thick as its face is ahead of the tool point (pad_front) either side, and
  // pad_half_width either side of the push line.
  const double back = -arm.nudge.start_distance - arm.nudge.pad_front, front = -arm.nudge.stop_distance + arm.nudge.pad_front;
  const double gap_along = std::max({0.0, back - along, along - front});
  const double to_pad = std::hypot(gap_along, std::max(0.0, across - params.pad_half_width));
  if (to_pad < params.object_radius)
    return {PushConflict::Kind::Pad, "the pad would touch the " + what + " at " + millimetres(other)};
  // The pushed object slides up to `travel` ahead: a band two object radii wide.
  if (along >= 0 && along <= params.travel + 2 * params.object_radius && across < 2 * params.object_radius)
    return {PushConflict::Kind::Slide, "the pushed object may slide into the " + what + " at " + millimetres(other)};
  return {};
}

bool near_any(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& places, double radius) {
  return std::any_of(places.begin(), places.end(), [&](const Eigen::Vector3d& e) { return horizontal(e - p).norm() < radius; });
}

namespace {

// Every joint position the arm passes through executing `steps` from `seed`, as waypoints of a
// piecewise-linear joint path (a Move is a straight joint line to its goal).
std::vector<robot::JointVector> joint_waypoints(const std::vector<robot::MotionStep>& steps, const robot::JointVector& seed) {
  std::vector<robot::JointVector> waypoints = {seed};
  for (const robot::MotionStep& step : steps) {
    if (step.kind == robot::MotionStep::Kind::Move) waypoints.push_back(step.goal);
    if (step.kind == robot::MotionStep::Kind::Path) waypoints.insert(waypoints.end(), step.path.begin(), step.path.end());
  }
  return waypoints;
}

}  // namespace

PushConflict links_conflict(const robot::MotionPlan& plan, const robot::JointVector& seed,
                            const std::vector<Obstacle>& obstacles, const ArmSetup& arm, const TargetParams& params) {
  if (!(params.obstacle_height > 0) || obstacles.empty()) return {};
  std::vector<robot::JointVector> waypoints = joint_waypoints(plan.steps, seed);
  waypoints.push_back(arm.home());  // the arm parks after the push, before the after still
  const robot::SafetyConfig safety = arm.safety_config();
  PushConflict first;
  for (const Obstacle& other : obstacles) {
    if (first && !other.known) continue;  // only a known object's conflict outranks the first
    const double height = other.height > 0 ? other.height : params.obstacle_height;
    const robot::StandingObject object{arm.point_to_base(other.place), params.object_radius, height};
    const double gap = robot::least_link_gap_along(arm.model, safety, object, waypoints);
    if (gap >= arm.nudge.link_clearance) continue;
    PushConflict conflict{other.known ? PushConflict::Kind::KnownLinks : PushConflict::Kind::Links,
                          "the arm's links would pass within " + std::to_string(std::lround(1e3 * std::max(0.0, gap))) +
                              " mm of the " + other.what + " at " + millimetres(other.place)};
    if (other.known) return conflict;
    first = conflict;
  }
  return first;
}

namespace {

// The first of `obstacles` within `radius` of `p` (horizontally), or their end.
template <typename Obstacles>
auto obstacle_near(Obstacles& obstacles, const Eigen::Vector3d& p, double radius) {
  return std::find_if(obstacles.begin(), obstacles.end(), [&](const Obstacle& o) { return horizontal(o.place - p).norm() < radius; });
}

// The places a push must keep clear of: the other candidates that count as objects, the
// explored objects standing where no candidate is (their lines left out of the survey), and the
// objects only one camera's lines show.
std::vector<Obstacle> obstacles_to(const Candidate& c, const std::vector<Candidate>& candidates, const History& history,
                                   const TargetParams& params) {
  std::vector<Obstacle> obstacles;
  auto far_from_target = [&](const Eigen::Vector3d& p) { return horizontal(p - c.position).norm() >= params.same_object_radius; };
  auto near_an_obstacle = [&](const Eigen::Vector3d& p) {
    return obstacle_near(obstacles, p, params.same_object_radius) != obstacles.end();
  };
  for (const Candidate& other : candidates) {
    if (other.index == c.index || near_any(other.position, history.empty, params.explored_radius)) continue;
    if (other.stereo_agreement < params.min_stereo_agreement) continue;
    if (far_from_target(other.position)) obstacles.push_back({other.position, "candidate"});
  }
  for (const ExploredObject& object : history.standing) {
    if (!far_from_target(object.place)) continue;
    const auto near = obstacle_near(obstacles, object.place, params.same_object_radius);
    if (near == obstacles.end()) {
      obstacles.push_back({object.place, "explored object", object.height, true});
    } else if (near->height <= 0) {
      near->height = object.height;  // the candidate is the explored object's line seen again: as tall as measured
      near->known = true;
    }
  }
  for (const Eigen::Vector3d& object : history.sighted)
    if (far_from_target(object) && !near_an_obstacle(object)) obstacles.push_back({object, "object seen in one camera"});
  return obstacles;
}

// TargetParams::spare_doubtful: the candidates seen in too few of the survey's frames to be
// obstacles_to's, but often enough to be nudged themselves, that a push of `c` would rather keep
// clear of (not where `obstacles` already stands).
std::vector<Obstacle> doubtful_near(const Candidate& c, const std::vector<Candidate>& candidates, const History& history,
                                    const std::vector<Obstacle>& obstacles, const TargetParams& params) {
  std::vector<Obstacle> doubtful;
  if (!params.spare_doubtful) return doubtful;
  for (const Candidate& other : candidates) {
    if (other.index == c.index || near_any(other.position, history.empty, params.explored_radius)) continue;
    if (other.stereo_agreement >= params.min_stereo_agreement || other.stereo_agreement < params.min_nudge_agreement) continue;
    if (horizontal(other.position - c.position).norm() < params.same_object_radius) continue;
    if (obstacle_near(obstacles, other.position, params.same_object_radius) != obstacles.end()) continue;
    doubtful.push_back({other.position, "doubtful candidate"});
  }
  return doubtful;
}

// A push of `c` along `direction` planned with the arm's links clearing an object `height` tall:
// the robot library's plan, and the whole command as the arm service will plan it from where the
// arm is (the move to P0 included): a target it would refuse is not chosen.
struct PushPlan {
  robot::NudgePlan plan;
  robot::MotionPlan command;  // the arm service's steps, the move to P0 included
  std::string problem;        // empty when both plan
  bool ok() const { return problem.empty(); }
};
PushPlan plan_push(const Candidate& c, const Eigen::Vector3d& direction_base, const Eigen::Vector3d& direction,
                   const ArmSetup& arm, const robot::JointVector& seed, double height) {
  robot::NudgeParams nudge = arm.nudge;
  nudge.object_height = height;
  PushPlan push;
  push.plan = robot::plan_nudge(arm.model, arm.safety_config(), arm.point_to_base(c.position), direction_base, nudge, seed);
  if (!push.plan.ok()) {
    push.problem = "out of reach: " + push.plan.reason;
    return push;
  }
  robot::Command command;
  command.kind = robot::CommandKind::Nudge;
  command.target_position = c.position;
  command.direction = horizontal(direction).normalized();
  command.object_height = height;
  push.command = robot::plan_command(arm.planner(), command, seed);
  if (!push.command.ok()) push.problem = "the arm would refuse: " + push.command.reason;
  return push;
}

// The tallest object a push that does not clear the tallest expected (arm.nudge.object_height)
// still clears, down to params.shortest_height_limit, bisected to params.height_limit_step (a
// shorter object only leaves more room), and the push planned for it; nothing when it clears not
// even that (a push refused for reach or joint limits is refused at every height).
std::optional<std::pair<double, PushPlan>> push_for_shorter_object(const Candidate& c, const Eigen::Vector3d& direction_base,
                                                                   const Eigen::Vector3d& direction, const ArmSetup& arm,
                                                                   const robot::JointVector& seed, const TargetParams& params) {
  const double tallest = arm.nudge.object_height;
  if (!(params.shortest_height_limit > 0) || tallest <= params.shortest_height_limit) return std::nullopt;
  PushPlan low = plan_push(c, direction_base, direction, arm, seed, params.shortest_height_limit);
  if (!low.ok()) return std::nullopt;
  double clears = params.shortest_height_limit, refused = tallest;
  const double step = std::max(params.height_limit_step, 1e-4);  // a step of 0 or less would never end
  while (refused - clears > step) {
    const double middle = 0.5 * (clears + refused);
    PushPlan tried = plan_push(c, direction_base, direction, arm, seed, middle);
    if (tried.ok()) {
      clears = middle;
      low = std::move(tried);
    } else {
      refused = middle;
    }
  }
  return std::make_pair(clears, std::move(low));
}

// The horizontal push directions tried for a target (base frame): the two across the camera's view
// (thesis), then each turned by push_turn_step_deg, 2 push_turn_step_deg, ... up to
// max_push_turn_deg towards and away from the camera, in that order; with the angle turned.
// With other_way_first, across[1] and its turns come before across[0]'s.
std::vector<std::pair<Eigen::Vector3d, double>> push_directions(const Eigen::Vector3d& camera_base, const Eigen::Vector3d& target_base,
                                                                const TargetParams& params, bool other_way_first) {
  auto across = robot::directions_across_view(camera_base, target_base);
  if (other_way_first) std::swap(across[0], across[1]);
  std::vector<std::pair<Eigen::Vector3d, double>> out = {{across[0], 0.0}, {across[1], 0.0}};
  if (!(params.push_turn_step_deg > 0)) return out;
  // Below 90 deg: a push along the ray moves the object in depth only, which no camera sees as motion.
  for (double turn = params.push_turn_step_deg; turn <= params.max_push_turn_deg + 1e-9 && turn < 90; turn += params.push_turn_step_deg)
    for (const Eigen::Vector3d& d : across)
      for (double sign : {1.0, -1.0})
        out.emplace_back(Eigen::AngleAxisd(sign * turn * M_PI / 180, Eigen::Vector3d::UnitZ()) * d, turn);
  return out;
}

// Whether the arm could grasp the object where a push along `direction_base` would leave it
// (TargetParams::rest_travel along it; the grasp the supervisor will ask for, at the lowest usual
// height, planned by the arm service's own planner).
bool graspable_after_push(const Candidate& c, const Eigen::Vector3d& direction_base, const ArmSetup& arm,
                          const robot::JointVector& seed, const TargetParams& params) {
  robot::Command grasp;
  grasp.kind = robot::CommandKind::Grasp;
  grasp.target_position = c.position + params.rest_travel * horizontal(arm.direction_to_world(direction_base)).normalized();
  grasp.height = params.rest_grasp_height;
  return robot::plan_command(arm.planner(), grasp, seed).ok();
}

// TargetParams::rest_travel: whether the second way across the view leaves the object graspable
// and the first does not.
bool other_way_first(const Candidate& c, const Eigen::Vector3d& camera_base, const ArmSetup& arm,
                     const robot::JointVector& seed, const TargetParams& params) {
  if (!(params.rest_travel > 0)) return false;
  const auto across = robot::directions_across_view(camera_base, arm.point_to_base(c.position));
  return !graspable_after_push(c, across[0], arm, seed, params) && graspable_after_push(c, across[1], arm, seed, params);
}

// Which conflicts with other objects a pass over the candidates accepts (and notes): none, the
// pushed object's slide, or the slide and the arm's links. The pad's never.
enum class Tolerance { None, Slide, SlideAndLinks };

bool tolerated(PushConflict::Kind kind, Tolerance tolerance) {
  switch (kind) {
    case PushConflict::Kind::None: return true;
    case PushConflict::Kind::Slide: return tolerance != Tolerance::None;
    case PushConflict::Kind::Links: return tolerance == Tolerance::SlideAndLinks;
    case PushConflict::Kind::KnownLinks: return false;  // a found object is not knocked over for a maybe
    case PushConflict::Kind::Pad: return false;
  }
  return false;
}

// Both conflicts of a push, for its note: the kind of the worse (the links), both reasons.
PushConflict either(const PushConflict& pad_or_slide, const PushConflict& links) {
  if (!links) return pad_or_slide;
  if (!pad_or_slide) return links;
  return {links.kind, pad_or_slide.reason + "; " + links.reason};
}

// The conflict with `obstacles` that decides a push of `c` along `direction` (pad and slide): a
// pad's, else the first found.
PushConflict pad_or_slide_conflict(const Candidate& c, const Eigen::Vector3d& direction, const std::vector<Obstacle>& obstacles,
                                   const ArmSetup& arm, const TargetParams& params) {
  PushConflict conflict;
  for (const Obstacle& other : obstacles) {
    PushConflict found = push_conflict(c.position, direction, other.place, arm, params, other.what);
    if (found.kind == PushConflict::Kind::Pad) return found;
    if (found && !conflict) conflict = found;
  }
  return conflict;
}

// Whether a push of `c` along `direction`, its command `push`, keeps clear of every one of
// `places`: the pad, the pushed object's slide and the arm's links.
bool keeps_clear_of(const Candidate& c, const Eigen::Vector3d& direction, const robot::MotionPlan& push,
                    const std::vector<Obstacle>& places, const ArmSetup& arm, const robot::JointVector& seed,
                    const TargetParams& params) {
  return !pad_or_slide_conflict(c, direction, places, arm, params) && !links_conflict(push, seed, places, arm, params);
}

// The pushes of a candidate along each of its directions (push_directions), each worked out once,
// when first asked for: the doubtful-sparing search and the pass that follows it ask for the same
// directions, and planning a push (the robot library's plan and the arm service's) is the costly
// part. A push is planned only when the pass's tolerance accepts its pad and slide conflict, and
// its links are checked only when it plans.
class PushTrials {
 public:
  struct Trial {
    Eigen::Vector3d direction_base, direction;  // base and world frame
    double turn = 0;
    PushConflict conflict;  // the pad's or the slide's
    bool planned = false;   // whether `push` was planned (the conflict tolerated)
    PushPlan push;          // at the tallest object's height
    PushConflict links;     // when `push` planned
    // Whether the pass takes this push as it is (the tallest object cleared).
    bool accepted(Tolerance tolerance) const { return planned && push.ok() && tolerated(links.kind, tolerance); }
  };

  PushTrials(const Candidate& c, std::vector<std::pair<Eigen::Vector3d, double>> directions, const std::vector<Obstacle>& obstacles,
             const ArmSetup& arm, const robot::JointVector& seed, const TargetParams& params, Tolerance tolerance)
      : c_(c), directions_(std::move(directions)), obstacles_(obstacles), arm_(arm), seed_(seed), params_(params),
        tolerance_(tolerance), trials_(directions_.size()) {}

  size_t size() const { return directions_.size(); }

  const Trial& operator[](size_t i) {
    if (!trials_[i]) trials_[i] = work_out(i);
    return *trials_[i];
  }

 private:
  Trial work_out(size_t i) const {
    Trial t;
    t.direction_base = directions_[i].first;
    t.turn = directions_[i].second;
    t.direction = arm_.direction_to_world(t.direction_base);
    t.conflict = pad_or_slide_conflict(c_, t.direction, obstacles_, arm_, params_);
    if (!tolerated(t.conflict.kind, tolerance_)) return t;
    t.planned = true;
    t.push = plan_push(c_, t.direction_base, t.direction, arm_, seed_, arm_.nudge.object_height);
    if (t.push.ok()) t.links = links_conflict(t.push.command, seed_, obstacles_, arm_, params_);
    return t;
  }

  const Candidate& c_;
  const std::vector<std::pair<Eigen::Vector3d, double>> directions_;
  const std::vector<Obstacle>& obstacles_;
  const ArmSetup& arm_;
  const robot::JointVector& seed_;
  const TargetParams& params_;
  const Tolerance tolerance_;
  std::vector<std::optional<Trial>> trials_;
};

// The first of `trials` the `tolerance` accepts that also keeps clear of every one of
// `doubtful`; nothing when none does (or there is nothing doubtful to spare).
std::optional<size_t> push_sparing(const Candidate& c, PushTrials& trials, const std::vector<Obstacle>& doubtful,
                                   const ArmSetup& arm, const robot::JointVector& seed, const TargetParams& params,
                                   Tolerance tolerance) {
  if (doubtful.empty()) return std::nullopt;
  for (size_t i = 0; i < trials.size(); ++i) {
    const PushTrials::Trial& t = trials[i];
    if (t.accepted(tolerance) && keeps_clear_of(c, t.direction, t.push.command, doubtful, arm, seed, params)) return i;
  }
  return std::nullopt;
}

// Whether the `tolerance` accepts any of `trials` as it is.
bool any_accepted(PushTrials& trials, Tolerance tolerance) {
  for (size_t i = 0; i < trials.size(); ++i)
    if (trials[i].accepted(tolerance)) return true;
  return false;
}

// What a pass made of one candidate: the push taken, the candidate rejected (its reason noted),
// or deferred (TargetParams::defer_for_doubtful).
struct Rejected {};
struct Deferred {};
using CandidateOutcome = std::variant<TargetChoice, Rejected, Deferred>;

// Whether a candidate at `p` was nudged already (the place explored, or a phantom's).
bool nudged_already(const Eigen::Vector3d& p, const History& history, const TargetParams& params) {
  return near_any(p, history.explored, params.explored_radius) || near_any(p, history.phantoms, params.phantom_radius);
}

// The doubtful places (doubtful_near) where no candidate was nudged yet: the ones a pass may still
// try.
std::vector<Obstacle> not_yet_nudged(const std::vector<Obstacle>& doubtful, const History& history, const TargetParams& params) {
  std::vector<Obstacle> untried;
  for (const Obstacle& d : doubtful)
    if (!nudged_already(d.place, history, params)) untried.push_back(d);
  return untried;
}

// One candidate of a pass (choose_pass): `choice` holds the rejections so far, and a taken push
// carries them.
CandidateOutcome try_candidate(const Candidate& c, TargetChoice& choice, const std::vector<Candidate>& candidates,
                               const History& history, const Eigen::Vector3d& camera_base, const ArmSetup& arm,
                               const robot::JointVector& seed, const TargetParams& params, Tolerance tolerance, bool may_defer) {
  auto reject = [&](const std::string& reason) {
    choice.rejected.push_back({c.index, c.position, reason});
    return Rejected{};
  };
  if (nudged_already(c.position, history, params)) return reject("already explored");
  if (c.stereo_agreement < params.min_nudge_agreement) return reject("not seen upright by both cameras (a stereo mismatch)");
  std::string why_not;  // the two pushes across the view: their reasons in full
  int turned_refused = 0;
  std::vector<const PushTrials::Trial*> too_near;  // planned only for a shorter object, perhaps
  auto taken = [&](const Eigen::Vector3d& direction, double turn, const PushConflict& conflict, PushPlan push, double limit) {
    TargetChoice t = choice;
    t.found = true;
    t.target = c;
    t.direction = horizontal(direction).normalized();
    t.plan = std::move(push.plan);
    t.height_limit = limit;
    t.push_turn_deg = turn;
    if (conflict) t.note = "no clear push left: " + conflict.reason;
    if (turn > 0) t.note += std::string(t.note.empty() ? "" : "; ") + "pushed " + std::to_string(std::lround(turn)) + " deg off across the view";
    return t;
  };
  const std::vector<Obstacle> obstacles = obstacles_to(c, candidates, history, params);
  const bool swapped = other_way_first(c, camera_base, arm, seed, params);
  PushTrials trials(c, push_directions(camera_base, arm.point_to_base(c.position), params, swapped), obstacles, arm, seed,
                    params, tolerance);
  const std::vector<Obstacle> doubtful = doubtful_near(c, candidates, history, obstacles, params);
  // TargetParams::defer_for_doubtful: a candidate that counts as an object, every push of which
  // endangers a doubtful candidate not yet nudged, waits (choose_in_order says till when).
  // (One with no push the pass accepts at all is not deferred: it is rejected below.)
  std::optional<size_t> spared;  // TargetParams::spare_doubtful: the first push clear of them all
  if (may_defer && params.defer_for_doubtful && c.stereo_agreement >= params.min_stereo_agreement) {
    const std::vector<Obstacle> untried = not_yet_nudged(doubtful, history, params);
    if (!untried.empty() && any_accepted(trials, tolerance)) {
      const std::optional<size_t> spares_untried = push_sparing(c, trials, untried, arm, seed, params, tolerance);
      if (!spares_untried) return Deferred{};
      if (untried.size() == doubtful.size()) spared = spares_untried;  // the same places: not searched again
    }
  }
  if (!spared) spared = push_sparing(c, trials, doubtful, arm, seed, params, tolerance);
  if (spared) {
    const PushTrials::Trial& t = trials[*spared];
    return taken(t.direction, t.turn, either(t.conflict, t.links), t.push, 0.0);
  }
  for (size_t k = 0; k < trials.size(); ++k) {
    const PushTrials::Trial& t = trials[k];
    auto refuse = [&](const std::string& problem) {
      if (t.turn > 0) ++turned_refused;
      else why_not += std::string(why_not.empty() ? "" : "; the other way: ") + problem;
    };
    if (!t.planned) {
      refuse(t.conflict.reason);
      continue;
    }
    if (t.push.ok()) {
      if (!tolerated(t.links.kind, tolerance)) {
        refuse(t.links.reason);
        continue;
      }
      return taken(t.direction, t.turn, either(t.conflict, t.links), t.push, 0.0);
    }
    refuse(t.push.problem);
    too_near.push_back(&t);
  }
  std::optional<TargetChoice> limited;
  for (const PushTrials::Trial* r : too_near) {
    auto shorter = push_for_shorter_object(c, r->direction_base, r->direction, arm, seed, params);
    if (!shorter) continue;
    const PushConflict links = links_conflict(shorter->second.command, seed, obstacles, arm, params);
    if (!tolerated(links.kind, tolerance)) continue;
    if (!limited || shorter->first > limited->height_limit)
      limited = taken(r->direction, r->turn, either(r->conflict, links), std::move(shorter->second), shorter->first);
  }
  if (limited) return *limited;
  if (turned_refused > 0)
    why_not += "; pushes turned up to " + std::to_string(std::lround(params.max_push_turn_deg)) + " deg off across the view: none planned";
  return reject(why_not);
}

// One pass over the candidates in camera order: a push whose conflict with another object the
// `tolerance` does not accept is refused; one it accepts is taken and noted. Per candidate, the
// first push (in push_directions' order) that clears the tallest object expected is taken; when
// none does, the one that clears the tallest shorter object (TargetChoice::height_limit).
// With `waiting`, a candidate that waits for a doubtful one (TargetParams::defer_for_doubtful) is
// passed over, noted, and added to it (once); without, none waits.
TargetChoice choose_pass(const std::vector<Candidate>& candidates, const std::vector<size_t>& order, const History& history,
                         const Eigen::Vector3d& camera_base, const ArmSetup& arm, const robot::JointVector& seed,
                         const TargetParams& params, Tolerance tolerance, std::vector<size_t>* waiting) {
  TargetChoice choice;
  for (size_t i : order) {
    const Candidate& c = candidates[i];
    CandidateOutcome outcome = try_candidate(c, choice, candidates, history, camera_base, arm, seed, params, tolerance, waiting != nullptr);
    if (auto* taken = std::get_if<TargetChoice>(&outcome)) return std::move(*taken);
    if (!std::holds_alternative<Deferred>(outcome)) continue;
    choice.rejected.push_back({c.index, c.position, "waits: every push would pass by a doubtful candidate not yet nudged"});
    if (std::find(waiting->begin(), waiting->end(), i) == waiting->end()) waiting->push_back(i);
  }
  return choice;
}

}  // namespace

namespace {

// The strict pass over the candidates in `order`, then the relaxed ones when it finds nothing.
// Candidates waiting for a doubtful one (TargetParams::defer_for_doubtful) are tried after the
// others' strict and slide passes (a push that may slide an object into a candidate risks less
// than one whose pad comes down by a real object the survey doubted), and before the pass that
// lets the links pass near candidates.
TargetChoice choose_in_order(const std::vector<Candidate>& candidates, const std::vector<size_t>& order, const History& history,
                             const Eigen::Vector3d& right_camera, const ArmSetup& arm, const robot::JointVector& seed,
                             const TargetParams& params) {
  const Eigen::Vector3d camera_base = arm.point_to_base(right_camera);
  auto pass = [&](const std::vector<size_t>& which, Tolerance tolerance, std::vector<size_t>* waiting) {
    return choose_pass(candidates, which, history, camera_base, arm, seed, params, tolerance, waiting);
  };
  std::vector<size_t> waiting;
  TargetChoice strict = pass(order, Tolerance::None, &waiting);
  if (strict.found) return strict;
  TargetChoice relaxed = pass(order, Tolerance::Slide, &waiting);
  for (Tolerance tolerance : {Tolerance::None, Tolerance::Slide})
    if (!relaxed.found && !waiting.empty()) relaxed = pass(waiting, tolerance, nullptr);
  if (!relaxed.found) relaxed = pass(order, Tolerance::SlideAndLinks, nullptr);
  if (!relaxed.found) {
    // The strict pass's reasons say why each was passed over (none waiting: all were tried).
    return waiting.empty() ? strict : pass(order, Tolerance::None, nullptr);
  }
  // Keep the strict pass's reasons for the candidates passed over before the chosen one.
  relaxed.rejected.clear();
  for (const Rejection& r : strict.rejected)
    if (r.index != relaxed.target.index) relaxed.rejected.push_back(r);
  return relaxed;
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
    if (params.order == TargetParams::Order::MostSupport && candidates[a].support != candidates[b].support)
      return candidates[a].support > candidates[b].support;
    return (candidates[a].position - right_camera).norm() < (candidates[b].position - right_camera).norm();
  });
  return choose_in_order(candidates, order, history, right_camera, arm, seed, params);
}

TargetChoice choose_push_for(const std::vector<Candidate>& candidates, size_t which, const History& history,
                             const Eigen::Vector3d& right_camera, const ArmSetup& arm, const robot::JointVector& seed,
                             const TargetParams& params) {
  if (which >= candidates.size())
    throw std::out_of_range("choose_push_for: candidate " + std::to_string(which) + " of " + std::to_string(candidates.size()));
  return choose_in_order(candidates, {which}, history, right_camera, arm, seed, params);
}

}  // namespace nudge::supervisor
