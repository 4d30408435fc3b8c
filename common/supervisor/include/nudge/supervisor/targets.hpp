#pragma once
// Which candidate to nudge next (thesis sec. 6.2-6.3, fig. 6.2): the candidate nearest the right
// camera that is nudgeable, i.e. the arm can plan the push (reach, joint limits, table, workspace
// ring, self-collision: the robot library's own checks, the same the arm service applies) and the
// push would not touch another candidate. Every candidate passed over gets its reason.
#include <Eigen/Core>

#include <string>
#include <vector>

#include "nudge/robot/command_planner.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::supervisor {

// Where the arm stands in the world frame (docs/robot.md, "Frames"): its base on the world z axis
// `base.height` above the table top, turned `base.yaw` about z (robot::BaseFrame).
struct ArmSetup {
  robot::ArmModel model = robot::puma260();
  robot::SafetyConfig safety;
  robot::NudgeParams nudge;
  robot::BaseFrame base;  // the workspace file's, in the service

  // The safety checks with the table where the base height puts it.
  robot::SafetyConfig safety_config() const;
  // The arm service's planner configuration for this arm: a nudge it accepts is one it can plan.
  robot::PlannerConfig planner() const;
  // Where the arm parks (the arm service's COMMAND_HOME pose): the planner's seed before any ARM_STATE.
  robot::JointVector home() const;
  Eigen::Vector3d point_to_base(const Eigen::Vector3d& world) const { return base.point_to_base(world); }
  Eigen::Vector3d direction_to_base(const Eigen::Vector3d& world) const { return base.direction_to_base(world); }
  Eigen::Vector3d direction_to_world(const Eigen::Vector3d& in_base) const {
    return base.world_from_base().linear() * in_base;
  }
};

struct TargetParams {
  double object_radius = 0.045;   // the largest expected object (thesis: mugs, bottles)
  double travel = 0.04;           // how far a nudged object may slide beyond P2
  double explored_radius = 0.05;  // a candidate this close to a place already explored is skipped (two objects stand farther apart)
  // A candidate this close to a place where a push moved nothing is that phantom seen again. A
  // phantom lies between the objects whose lines make it, 4 cm from them on a crowded table.
  double phantom_radius = 0.025;
  // Half the pad's width across the push direction: the simulated pad is 8 cm wide
  // (sim::pusher_pad_half_size().y(); a test keeps the two equal). It was 0.02 until 2026-12-01,
  // so the planner let the pad pass within 3 cm of the axis of a candidate 7 cm beside its path.
  double pad_half_width = 0.04;
  // Two candidates closer than this cannot both be objects: one is the other seen through a stereo
  // mismatch (it lies along the same viewing ray). Neither is an obstacle to the other's push, and
  // nudging one explores both.
  double same_object_radius = 0.06;
  // Candidates whose stereo agreement is below this are tried last and are no obstacle to others.
  double min_stereo_agreement = 0.5;
  // Beyond the thesis: some of those doubtful candidates are real objects (a cup seen in 28 % of
  // the frames, development2 hm1), and a push that passes its pad or the arm's links beside one
  // knocks it over. With this on, each candidate's pushes are tried first keeping clear of the
  // doubtful candidates (seen in at least min_nudge_agreement) as of the others: pad, slide and
  // links alike. When none of its pushes can, its pushes are chosen as without them. So the
  // doubtful ones change only which way a candidate is pushed (the order: defer_for_doubtful).
  bool spare_doubtful = true;
  // Beyond the thesis: when no push of a candidate that counts as an object keeps clear of the
  // doubtful candidates not yet nudged, it waits: the other candidates (the doubtful ones among
  // them) are tried first, with clear pushes and then with pushes that may slide the object into
  // another candidate, and the waiting ones only when none of those is taken (before pushes whose
  // links pass near a candidate). A doubtful candidate that is real is then nudged before a push
  // can knock it over (hm1's cup, under the bottle's pad); one that is a phantom costs one push
  // that moves nothing, after which the waiting candidate's push is chosen as without the rule.
  // Candidates with no push the pass accepts do not wait. Needs spare_doubtful.
  bool defer_for_doubtful = true;
  // The order the others are tried in. Nearest the right camera first is the thesis'. Beyond it:
  // the most intersects first (Candidate::support, nearest first among equals). A phantom, made
  // by lines of two objects, holds in fewer of a survey's frames than an object's own lines, and
  // a phantom's push sweeps the gap between objects the survey may not have found.
  enum class Order { NearestCamera, MostSupport };
  Order order = Order::NearestCamera;
  // Below this, not nudged at all: in no frame of the survey did both cameras show a line where
  // an upright axis standing there projects. Held-out runs (2026-11-25): every candidate seen 0%
  // was nowhere near an object, and two of their pushes moved a neighbour and gave false
  // segmentations (h06, hm1); but a transparent bottle was seen in only 4% (second set, h11), so
  // only the never-seen are passed over.
  double min_nudge_agreement = 0.01;
  // A push whose arm would come too near an object as tall as the tallest expected
  // (robot::NudgeParams::object_height) may still clear the object that stands there: the choice
  // then carries the tallest object it clears (to within height_limit_step), down to this, and the
  // object's height must be measured before the push (object_height.hpp). 0: no such pushes.
  double shortest_height_limit = 0.08;
  double height_limit_step = 0.005;
  // When neither push across the camera's view (thesis) plans, pushes turned off it by multiples
  // of push_turn_step_deg up to max_push_turn_deg are tried: the object still moves across the
  // view by cos(turn) of the push, and a place the arm reaches one way only (joint 3's limit, the
  // workspace ring) may be pushed. 0: across the view only.
  double max_push_turn_deg = 40;
  double push_turn_step_deg = 20;
  // The arm's links (upper arm, forearm, tool) along the whole command, the move to P0 included,
  // keep robot::NudgeParams::link_clearance from every other known object, taken as an upright
  // column of object_radius and, unless the stills measured it (an explored object), this height
  // (the tallest expected). A push that cannot is taken only when no push clears every object.
  // 0: not checked.
  double obstacle_height = 0.25;
  // Beyond the thesis (which does not say which way across the view to push): with learning on,
  // the pushed object is grasped where it comes to rest, and a push towards the arm's base can
  // leave it where no grasp plans (joint 3's limit: the demo's bottle, segmented but not learned).
  // When > 0, of the two ways across the view the one whose expected rest (rest_travel along the
  // push) the arm can grasp at rest_grasp_height is tried first (with its turned pushes); the
  // other way stays, after it. 0: across[0] first, as before.
  double rest_travel = 0;
  double rest_grasp_height = 0.06;  // fingers above the table: a 12 cm cup's grip, the lowest usual
};

struct Candidate {
  int index = 0;                   // in the CANDIDATES message
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame, on the table
  int support = 0;                 // intersects in its cluster
  // Fraction of the survey's stereo pairs in which BOTH cameras detected a line where this axis
  // projects. A stereo mismatch (a left line paired with the wrong right line) gives a candidate
  // along one camera's viewing ray at the wrong depth: the other camera has no line there.
  double stereo_agreement = 1.0;
};

struct Rejection {
  int index = 0;
  Eigen::Vector3d position;
  std::string reason;
};

struct TargetChoice {
  bool found = false;
  Candidate target;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // push direction, world frame, horizontal
  robot::NudgePlan plan;                                  // base frame (for pictures and checks)
  std::vector<Rejection> rejected;                        // every candidate passed over, and why
  std::string note;  // set when the push was accepted although it may touch another candidate
  // 0: the push clears the tallest object expected. Otherwise it clears only an object this tall
  // (m above the table): the object must be measured no taller before it is pushed.
  double height_limit = 0;
  double push_turn_deg = 0;  // how far the push is turned off across the camera's view
};

// "(x, y) mm" of a world point, for reasons.
std::string millimetres(const Eigen::Vector3d& p);

// An explored object where it stands now (world frame, on the table), and how tall the stills
// measured it (m above the table, the measurement's margin included; 0: not measured, and taken
// as TargetParams::obstacle_height).
struct ExploredObject {
  Eigen::Vector3d place;
  double height = 0;
  ExploredObject(const Eigen::Vector3d& place, double height = 0) : place(place), height(height) {}  // NOLINT: a place alone is an object not measured
};

// What the run's earlier attempts left on the table (world frame).
struct History {
  // Places already nudged (where a candidate stood, where a nudged object came to rest): skipped.
  std::vector<Eigen::Vector3d> explored;
  // Where a push moved nothing (phantoms): skipped within the smaller phantom_radius.
  std::vector<Eigen::Vector3d> phantoms;
  // Where a nudge found nothing: candidates there are no obstacle to other pushes.
  std::vector<Eigen::Vector3d> empty;
  // Explored objects where they stand now. Later surveys leave their lines out, so they may be
  // no candidate; they are still obstacles to every push.
  std::vector<ExploredObject> standing;
  // Where a line the right camera saw through most of the survey stands on the table
  // (Config::line_obstacle_share): an object the stereo pairing may have missed; an obstacle to
  // every push (one at a candidate that is itself an obstacle adds nothing).
  std::vector<Eigen::Vector3d> sighted;
};

// Candidates nearest the right camera first; the first nudgeable one that `history` does not
// rule out is chosen.
// Beyond the thesis (one object per scene): on a crowded table every push may pass near another
// candidate, many of them phantoms between two objects. When no push is clear, the nearest
// candidate whose push only risks sliding it into another candidate is nudged anyway (the nudge
// is gentle and short) and `note` says which; failing that, the nearest whose arm links may also
// pass near another object (TargetParams::obstacle_height). The pad itself never descends onto
// or sweeps through another candidate, and the strict rule decides whenever it can. A candidate
// waiting for a doubtful one (TargetParams::defer_for_doubtful) comes after the other candidates'
// clear and slide-risking pushes.
TargetChoice choose_target(const std::vector<Candidate>& candidates, const History& history, const Eigen::Vector3d& right_camera,
                           const ArmSetup& arm, const robot::JointVector& seed, const TargetParams& params = {});

// The push choose_target would plan for candidates[which] alone (the same passes and obstacles: the
// other candidates and `history`), whatever the order would have tried first. Not found when it
// has none. Throws std::out_of_range for an index past the list.
TargetChoice choose_push_for(const std::vector<Candidate>& candidates, size_t which, const History& history,
                             const Eigen::Vector3d& right_camera, const ArmSetup& arm, const robot::JointVector& seed,
                             const TargetParams& params = {});

// Whether pushing `target` along `direction` would touch `other`, and how: the pad itself on its
// way down at P1 and along P1 -> P2 (never acceptable), or the pushed object sliding into it
// (acceptable on a crowded table where `other` may be a phantom), or (links_conflict) the arm's
// links passing near it (acceptable last of all: its height is not known, and the tallest
// expected is assumed).
struct PushConflict {
  // KnownLinks: the links would sweep an explored object (one the robot has found, often learned
  // and put back): never tolerated, where sweeping a candidate (perhaps a phantom) is, last.
  enum class Kind { None, Pad, Slide, Links, KnownLinks };
  Kind kind = Kind::None;
  std::string reason;
  explicit operator bool() const { return kind != Kind::None; }
};
// `what` names `other` in the reason ("candidate", "explored object").
PushConflict push_conflict(const Eigen::Vector3d& target, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& other, const ArmSetup& arm, const TargetParams& params,
                           const std::string& what = "candidate");

// A place a push must keep clear of (world frame, on the table), and what stands there, for
// reasons ("candidate", "explored object").
struct Obstacle {
  Eigen::Vector3d place;
  const char* what = "candidate";
  double height = 0;  // m above the table as measured; 0: not measured (TargetParams::obstacle_height)
  bool known = false;  // an explored object standing there: real, and its links conflict is KnownLinks
};

// Whether the arm's links, at every joint position of `plan` (the arm service's steps for the
// push, executed from `seed`) and on the way home after it (where the arm parks), keep
// arm.nudge.link_clearance from an object params.object_radius wide standing at each of
// `obstacles`, as tall as it was measured (else params.obstacle_height); the first one they do not
// is named, a known one (KnownLinks) before any other. No conflict when params.obstacle_height is 0.
PushConflict links_conflict(const robot::MotionPlan& plan, const robot::JointVector& seed,
                            const std::vector<Obstacle>& obstacles, const ArmSetup& arm, const TargetParams& params);

// Whether `p` lies within `radius` of any of `places`, on the table (heights ignored).
bool near_any(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& places, double radius);

}  // namespace nudge::supervisor
