#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "nudge/robot/driver.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/trajectory.hpp"

using namespace nudge::robot;

namespace {

constexpr double kPoseTolerance = 1e-6;  // metres and radians

double position_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Vector3d difference = a.translation() - b.translation();
  return difference.norm();
}

// Angle of the rotation between the two orientations, radians.
double rotation_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Matrix3d relative = a.linear().transpose() * b.linear();
  return Eigen::AngleAxisd(relative).angle();
}

JointVector random_joints_within_limits(const ArmModel& model, std::mt19937& rng) {
  JointVector q;
  for (int j = 0; j < kNumJoints; ++j) {
    std::uniform_real_distribution<double> within(model.limits.lower[j], model.limits.upper[j]);
    q[j] = within(rng);
  }
  return q;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

Eigen::Isometry3d pose_at(const Eigen::Vector3d& position) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = position;
  return pose;
}

}  // namespace

// ---------------------------------------------------------------- model and forward kinematics

TEST(Puma260Model, MatchesTableB1) {
  const ArmModel model = puma260();
  const double alpha_deg[kNumJoints] = {90, 0, -90, 90, -90, 0};
  const double a[kNumJoints] = {0, 0.2032, 0, 0, 0, 0};
  const double d[kNumJoints] = {0, 0, 0.12624, 0.2032, 0, 0};
  for (int i = 0; i < kNumJoints; ++i) {
    EXPECT_DOUBLE_EQ(model.links[i].alpha, deg_to_rad(alpha_deg[i])) << "link " << i + 1;
    EXPECT_DOUBLE_EQ(model.links[i].a, a[i]) << "link " << i + 1;
    EXPECT_DOUBLE_EQ(model.links[i].d, d[i]) << "link " << i + 1;
    EXPECT_LT(model.limits.lower[i], model.limits.upper[i]);
  }
}

TEST(ForwardKinematics, ZeroConfigurationIsTheLShape) {
  // Upper arm horizontal along x, forearm up, shoulder offset d3 along -y; every rotation cancels.
  const ArmModel model = puma260();
  const Eigen::Isometry3d flange = flange_pose(model, JointVector::Zero());
  EXPECT_LT((flange.translation() - Eigen::Vector3d(0.2032, -0.12624, 0.2032)).norm(), 1e-12);
  EXPECT_LT((flange.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::Isometry3d tool = forward_kinematics(model, JointVector::Zero());
  EXPECT_LT((tool.translation() - Eigen::Vector3d(0.2032, -0.12624, 0.3532)).norm(), 1e-12);
}

TEST(ForwardKinematics, ArmStraightUp) {
  const ArmModel model = puma260();
  const Eigen::Isometry3d flange = flange_pose(model, joints_from_degrees(0, 90, -90, 0, 0, 0));
  EXPECT_LT((flange.translation() - Eigen::Vector3d(0, -0.12624, 0.4064)).norm(), 1e-12);
  EXPECT_LT((flange.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ForwardKinematics, ArmStretchedHorizontallyAlongY) {
  // theta1 = 90: the arm plane faces +y, the offset d3 now lies along +x; the stretched arm
  // (theta3 = -90) points the flange z axis along +y.
  const ArmModel model = puma260();
  const JointVector q = joints_from_degrees(90, 0, -90, 0, 0, 0);
  const Eigen::Isometry3d flange = flange_pose(model, q);
  EXPECT_LT((flange.translation() - Eigen::Vector3d(0.12624, 0.4064, 0)).norm(), 1e-12);
  EXPECT_LT((flange.linear().col(2) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  const Eigen::Vector3d tool = forward_kinematics(model, q).translation();
  EXPECT_LT((tool - Eigen::Vector3d(0.12624, 0.5564, 0)).norm(), 1e-12);
}

TEST(ForwardKinematics, WristCentreIgnoresWristJoints) {
  // A spherical wrist: joints 4-6 turn the flange about the wrist centre without moving it.
  const ArmModel model = puma260();
  const JointVector a = joints_from_degrees(20, 40, -120, 0, 0, 0);
  const JointVector b = joints_from_degrees(20, 40, -120, 70, -50, 130);
  EXPECT_LT(position_error(flange_pose(model, a), flange_pose(model, b)), 1e-12);
}

// ---------------------------------------------------------------- inverse kinematics

TEST(InverseKinematics, RoundTripsThousandsOfRandomConfigurations) {
  const ArmModel model = puma260();
  std::mt19937 rng(20080101);
  int exact_joint_matches = 0;
  constexpr int kSamples = 5000;
  for (int i = 0; i < kSamples; ++i) {
    const JointVector q = random_joints_within_limits(model, rng);
    const Eigen::Isometry3d pose = forward_kinematics(model, q);
    IkOptions options;
    options.configuration = configuration_of(model, q);
    options.seed = q;
    const IkResult ik = inverse_kinematics(model, pose, options);
    ASSERT_TRUE(ik.ok()) << "sample " << i << ": " << ik.reason;
    ASSERT_TRUE(ik.q.allFinite());
    const Eigen::Isometry3d again = forward_kinematics(model, ik.q);
    ASSERT_LT(position_error(pose, again), kPoseTolerance) << "sample " << i;
    ASSERT_LT(rotation_error(pose, again), kPoseTolerance) << "sample " << i;
    EXPECT_TRUE(check_joint_limits(model, ik.q).ok());
    if (!ik.wrist_singular) {
      EXPECT_LT(joint_distance(ik.q, q), 1e-6) << "sample " << i;
      ++exact_joint_matches;
    }
  }
  EXPECT_GT(exact_joint_matches, kSamples * 99 / 100);
}

TEST(InverseKinematics, EverySolutionReproducesThePose) {
  const ArmModel model = puma260();
  std::mt19937 rng(7);
  for (int i = 0; i < 500; ++i) {
    const JointVector q = random_joints_within_limits(model, rng);
    const Eigen::Isometry3d pose = forward_kinematics(model, q);
    const std::vector<JointVector> solutions = all_inverse_kinematics(model, pose, q);
    ASSERT_FALSE(solutions.empty()) << "sample " << i;
    for (const JointVector& solution : solutions) {
      const Eigen::Isometry3d again = forward_kinematics(model, solution);
      EXPECT_LT(position_error(pose, again), kPoseTolerance);
      EXPECT_LT(rotation_error(pose, again), kPoseTolerance);
    }
    const IkResult nearest = nearest_inverse_kinematics(model, pose, q);
    ASSERT_TRUE(nearest.ok()) << nearest.reason;
    EXPECT_LT(position_error(pose, forward_kinematics(model, nearest.q)), kPoseTolerance);
  }
}

TEST(InverseKinematics, ThesisConfigurationSolvesOrExplains) {
  // The thesis' single solution (right arm, elbow up, no flip) for arbitrary reachable poses:
  // either an exact solution or a joint-limit reason, never NaN.
  const ArmModel model = puma260();
  std::mt19937 rng(11);
  int solved = 0, in_thesis_configuration = 0;
  for (int i = 0; i < 2000; ++i) {
    const JointVector q = random_joints_within_limits(model, rng);
    const Eigen::Isometry3d pose = forward_kinematics(model, q);
    const IkResult ik = inverse_kinematics(model, pose);
    ASSERT_TRUE(ik.q.allFinite());
    // q itself is a solution in the thesis configuration within the limits: it must be found.
    const bool q_is_thesis_configuration = configuration_of(model, q) == kThesisConfiguration;
    in_thesis_configuration += q_is_thesis_configuration;
    if (q_is_thesis_configuration) {
      EXPECT_TRUE(ik.ok()) << "sample " << i << ": " << ik.reason;
    }
    if (ik.ok()) {
      ++solved;
      EXPECT_EQ(configuration_of(model, ik.q), kThesisConfiguration);
      EXPECT_LT(position_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
      EXPECT_LT(rotation_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
    } else {
      EXPECT_EQ(ik.failure, IkFailure::JointLimit);
      EXPECT_TRUE(contains(ik.reason, "joint")) << ik.reason;
    }
  }
  // One configuration of eight: about 2000 / 8 samples start in it (and are solved, above).
  EXPECT_GT(in_thesis_configuration, 150);
  EXPECT_GE(solved, in_thesis_configuration);
}

TEST(InverseKinematics, ConfigurationsAreDistinctAndRecognised) {
  // A pose comfortably inside the workspace has eight solutions, one per configuration.
  ArmModel model = puma260();
  model.limits.lower = JointVector::Constant(-2 * kPi);  // no limits: see every configuration
  model.limits.upper = JointVector::Constant(2 * kPi);
  const Eigen::Isometry3d pose =
      forward_kinematics(model, joints_from_degrees(10, 60, -150, 30, -40, 20));
  for (const ArmConfiguration& configuration : all_configurations()) {
    IkOptions options;
    options.configuration = configuration;
    const IkResult ik = inverse_kinematics(model, pose, options);
    ASSERT_TRUE(ik.ok()) << to_string(configuration) << ": " << ik.reason;
    EXPECT_EQ(configuration_of(model, ik.q), configuration) << to_string(configuration);
    EXPECT_LT(position_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
    EXPECT_LT(rotation_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
  }
}

TEST(InverseKinematics, WristSingularityIsSolvedOrRefusedOnRequest) {
  const ArmModel model = puma260();
  const JointVector q = joints_from_degrees(10, 60, -150, 25, 0, 40);  // theta5 = 0
  const Eigen::Isometry3d pose = forward_kinematics(model, q);
  IkOptions options;
  options.seed = joints_from_degrees(0, 0, 0, 25, 0, 0);
  const IkResult solved = inverse_kinematics(model, pose, options);
  ASSERT_TRUE(solved.ok()) << solved.reason;
  EXPECT_TRUE(solved.wrist_singular);
  EXPECT_NEAR(solved.q[3], deg_to_rad(25), 1e-9);  // joint 4 kept at the seed's value
  EXPECT_LT(position_error(pose, forward_kinematics(model, solved.q)), kPoseTolerance);
  EXPECT_LT(rotation_error(pose, forward_kinematics(model, solved.q)), kPoseTolerance);

  options.refuse_wrist_singularity = true;
  const IkResult refused = inverse_kinematics(model, pose, options);
  EXPECT_EQ(refused.failure, IkFailure::WristSingular);
  EXPECT_TRUE(contains(refused.reason, "singular")) << refused.reason;
}

TEST(InverseKinematics, WristFlippedOverIsSolvedLikeTheUpright) {
  // theta5 = pi (the PUMA 260's joint 5 stops at +-100 deg, so widen it): joints 4 and 6 then
  // turn about the same axis in opposite senses; joint 4 stays at the seed, joint 6 makes up the rest.
  ArmModel model = puma260();
  model.limits.lower[4] = -1.1 * kPi;
  model.limits.upper[4] = 1.1 * kPi;
  for (double theta4_deg : {25.0, -60.0}) {
    const JointVector q = joints_from_degrees(10, 60, -150, theta4_deg, 180, 40);
    const Eigen::Isometry3d pose = forward_kinematics(model, q);
    IkOptions options;
    options.configuration = configuration_of(model, q);
    options.seed = q;
    const IkResult solved = inverse_kinematics(model, pose, options);
    ASSERT_TRUE(solved.ok()) << solved.reason;
    EXPECT_TRUE(solved.wrist_singular);
    EXPECT_NEAR(solved.q[3], deg_to_rad(theta4_deg), 1e-9);
    EXPECT_NEAR(std::fabs(solved.q[4]), kPi, 1e-9);
    EXPECT_LT(position_error(pose, forward_kinematics(model, solved.q)), kPoseTolerance);
    EXPECT_LT(rotation_error(pose, forward_kinematics(model, solved.q)), kPoseTolerance) << theta4_deg;
  }
}

TEST(InverseKinematics, RejectsTooFarWithReason) {
  const ArmModel model = puma260();
  const IkResult ik = inverse_kinematics(model, pose_at({0.6, 0.0, 0.0}));
  EXPECT_EQ(ik.failure, IkFailure::OutOfReach);
  EXPECT_TRUE(contains(ik.reason, "reach")) << ik.reason;
  EXPECT_TRUE(ik.q.allFinite());
}

TEST(InverseKinematics, RejectsTooCloseWithReason) {
  const ArmModel model = puma260();
  // Wrist centre 5 cm from the joint 1 axis: inside the 12.6 cm shoulder offset cylinder.
  const IkResult ik = inverse_kinematics_flange(model, pose_at({0.05, 0.0, 0.1}));
  EXPECT_EQ(ik.failure, IkFailure::InsideInnerRadius);
  EXPECT_TRUE(contains(ik.reason, "shoulder offset")) << ik.reason;
  EXPECT_TRUE(ik.q.allFinite());
}

TEST(InverseKinematics, RejectsFarBelowTheBaseWithReason) {
  const ArmModel model = puma260();
  const IkResult ik = inverse_kinematics(model, tool_down_pose({0.2, 0.0, -0.7}, 0.0));
  EXPECT_EQ(ik.failure, IkFailure::OutOfReach);
  EXPECT_FALSE(ik.reason.empty());
  EXPECT_TRUE(ik.q.allFinite());
}

TEST(InverseKinematics, RejectsBelowTheTableAsUnsafe) {
  // Reachable for the bare arm, but under the table: the safe solver refuses with the reason.
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const Eigen::Isometry3d below = tool_down_pose({0.25, 0.0, safety.table_z - 0.03}, 0.0);
  ASSERT_TRUE(nearest_inverse_kinematics(model, below, home.q).ok());
  const IkResult ik = safe_inverse_kinematics(model, safety, below, home.q);
  EXPECT_EQ(ik.failure, IkFailure::Unsafe);
  EXPECT_TRUE(contains(ik.reason, "table")) << ik.reason;
}

TEST(InverseKinematics, RejectsInvalidPoses) {
  const ArmModel model = puma260();
  Eigen::Isometry3d nan_pose = pose_at({0.25, 0.0, 0.0});
  nan_pose.translation().x() = std::nan("");
  EXPECT_EQ(inverse_kinematics(model, nan_pose).failure, IkFailure::InvalidPose);
  Eigen::Isometry3d skewed = pose_at({0.25, 0.0, 0.0});
  skewed.linear()(0, 1) = 0.5;  // not a rotation
  EXPECT_EQ(inverse_kinematics(model, skewed).failure, IkFailure::InvalidPose);
}

TEST(InverseKinematics, RandomPosesNeverGiveNaN) {
  const ArmModel model = puma260();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-0.7, 0.7);
  std::normal_distribution<double> gaussian;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotation.toRotationMatrix();
    pose.translation() = Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    const IkResult ik = nearest_inverse_kinematics(model, pose, JointVector::Zero());
    ASSERT_TRUE(ik.q.allFinite()) << "sample " << i;
    if (ik.ok()) {
      EXPECT_LT(position_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
      EXPECT_LT(rotation_error(pose, forward_kinematics(model, ik.q)), kPoseTolerance);
    } else {
      EXPECT_FALSE(ik.reason.empty()) << "sample " << i;
    }
  }
}

// ---------------------------------------------------------------- trajectories

TEST(TrapezoidalMove, RespectsLimitsStartsAndEndsAtRestAndSynchronises) {
  const ArmModel model = puma260();
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector start = random_joints_within_limits(model, rng);
    const JointVector goal = random_joints_within_limits(model, rng);
    const TrapezoidalMove move(start, goal, model.max_speed, model.max_acceleration);
    const double duration = move.duration();
    ASSERT_GT(duration, 0);

    EXPECT_EQ(move.position(0.0), start);
    EXPECT_EQ(move.position(duration), goal);  // exactly, not approximately
    EXPECT_EQ(move.position(duration + 1.0), goal);
    EXPECT_EQ(move.velocity(0.0), JointVector::Zero());
    EXPECT_EQ(move.velocity(duration), JointVector::Zero());

    const JointVector delta = goal - start;
    bool some_joint_at_a_limit = false;
    constexpr int kSteps = 2000;
    for (int k = 0; k <= kSteps; ++k) {
      const double t = duration * k / kSteps;
      const JointVector v = move.velocity(t);
      const JointVector a = move.acceleration(t);
      const JointVector q = move.position(t);
      for (int j = 0; j < kNumJoints; ++j) {
        ASSERT_LE(std::fabs(v[j]), model.max_speed[j] * (1 + 1e-9)) << "joint " << j + 1;
        ASSERT_LE(std::fabs(a[j]), model.max_acceleration[j] * (1 + 1e-9)) << "joint " << j + 1;
        some_joint_at_a_limit = some_joint_at_a_limit ||
                                std::fabs(v[j]) > model.max_speed[j] * (1 - 1e-9) ||
                                std::fabs(a[j]) > model.max_acceleration[j] * (1 - 1e-9);
      }
      // All joints share one progress fraction: they start, cruise and stop together.
      int reference = 0;
      delta.cwiseAbs().maxCoeff(&reference);
      const double progress = (q[reference] - start[reference]) / delta[reference];
      for (int j = 0; j < kNumJoints; ++j) {
        ASSERT_NEAR(q[j], start[j] + progress * delta[j], 1e-9) << "joint " << j + 1;
      }
    }
    EXPECT_TRUE(some_joint_at_a_limit) << "trial " << trial << ": the move is not time-optimal";
  }
}

TEST(TrapezoidalMove, VelocityIsTheDerivativeOfPosition) {
  const ArmModel model = puma260();
  const JointVector start = joints_from_degrees(0, 45, -180, 0, -45, 0);
  const JointVector goal = joints_from_degrees(60, 90, -150, 30, -80, 90);
  const TrapezoidalMove move(start, goal, model.max_speed, model.max_acceleration);
  constexpr double h = 1e-6;
  for (double t = 0.01; t < move.duration(); t += move.duration() / 37) {
    const JointVector numeric = (move.position(t + h) - move.position(t - h)) / (2 * h);
    EXPECT_LT((numeric - move.velocity(t)).cwiseAbs().maxCoeff(), 1e-5) << "t = " << t;
  }
}

TEST(TrapezoidalMove, ShortMovesAreTriangularAndZeroMovesTakeNoTime) {
  const ArmModel model = puma260();
  const JointVector start = JointVector::Zero();
  JointVector goal = start;
  goal[0] = deg_to_rad(1.0);  // far too short to reach cruise speed
  const TrapezoidalMove short_move(start, goal, model.max_speed, model.max_acceleration);
  EXPECT_NEAR(short_move.duration(), 2.0 * short_move.acceleration_time(), 1e-12);
  EXPECT_LT(short_move.velocity(short_move.duration() / 2)[0], model.max_speed[0]);
  EXPECT_EQ(short_move.position(short_move.duration()), goal);

  const TrapezoidalMove no_move(start, start, model.max_speed, model.max_acceleration);
  EXPECT_EQ(no_move.duration(), 0.0);
  EXPECT_EQ(no_move.position(1.0), start);
  EXPECT_EQ(no_move.velocity(0.0), JointVector::Zero());
}

TEST(TrapezoidalMove, RefusesBadLimits) {
  JointVector speed = JointVector::Ones();
  speed[2] = 0.0;
  EXPECT_THROW(TrapezoidalMove(JointVector::Zero(), JointVector::Ones(), speed,
                               JointVector::Ones()),
               std::invalid_argument);
}

TEST(LinearTrajectory, InterpolatesWaypointsAtTheSpeedLimit) {
  const ArmModel model = puma260();
  const std::vector<JointVector> waypoints = {
      joints_from_degrees(0, 45, -180, 0, -45, 0), joints_from_degrees(10, 45, -180, 0, -45, 0),
      joints_from_degrees(10, 45, -180, 0, -45, 0),  // repeated: adds no segment
      joints_from_degrees(10, 60, -170, 20, -45, 90)};
  const LinearTrajectory trajectory = LinearTrajectory::at_speed(waypoints, model.max_speed);
  ASSERT_EQ(trajectory.waypoints().size(), 3u);
  EXPECT_EQ(trajectory.position(0.0), waypoints[0]);
  EXPECT_EQ(trajectory.position(trajectory.duration()), waypoints[3]);
  const double t1 = trajectory.waypoints()[1].time;
  EXPECT_LT((trajectory.position(t1) - waypoints[1]).cwiseAbs().maxCoeff(), 1e-12);
  // Halfway through the first segment, halfway between its ends.
  const JointVector middle = 0.5 * (waypoints[0] + waypoints[1]);
  EXPECT_LT((trajectory.position(0.5 * t1) - middle).cwiseAbs().maxCoeff(), 1e-12);
  for (double t = 0; t < trajectory.duration(); t += 0.01) {
    const JointVector v = trajectory.velocity(t);
    for (int j = 0; j < kNumJoints; ++j) EXPECT_LE(std::fabs(v[j]), model.max_speed[j] + 1e-12);
  }
  // The longest segment's limiting joint moves at its full speed.
  EXPECT_NEAR(std::fabs(trajectory.velocity(0.5 * t1)[0]), model.max_speed[0], 1e-12);
}

TEST(LinearTrajectory, RefusesTimesThatDoNotIncrease) {
  EXPECT_THROW(LinearTrajectory({{0.0, JointVector::Zero()}, {0.0, JointVector::Ones()}}),
               std::invalid_argument);
  EXPECT_THROW(LinearTrajectory({}), std::invalid_argument);
}

TEST(SampleTrajectory, EndsExactlyAtTheEnd) {
  const ArmModel model = puma260();
  const TrapezoidalMove move(JointVector::Zero(), joints_from_degrees(30, 20, -10, 0, 0, 45),
                             model.max_speed, model.max_acceleration);
  const std::vector<TimedJoints> samples = sample_trajectory(move, 0.01);
  ASSERT_GE(samples.size(), 2u);
  EXPECT_EQ(samples.front().time, 0.0);
  EXPECT_EQ(samples.back().time, move.duration());
  EXPECT_EQ(samples.back().q, move.position(move.duration()));
  for (size_t i = 1; i < samples.size(); ++i) EXPECT_GT(samples[i].time, samples[i - 1].time);
}

// ---------------------------------------------------------------- safety

TEST(Safety, WorkspaceRing) {
  const SafetyConfig safety;
  EXPECT_TRUE(check_workspace_ring(safety, {0.25, 0.0, -0.2}).ok());
  EXPECT_TRUE(check_workspace_ring(safety, {0.0, -0.15, -0.2}).ok());
  const CheckResult too_close = check_workspace_ring(safety, {0.1, 0.0, -0.2});
  EXPECT_FALSE(too_close.ok());
  EXPECT_TRUE(contains(too_close.reason, "ring")) << too_close.reason;
  EXPECT_FALSE(check_workspace_ring(safety, {0.3, 0.3, -0.2}).ok());  // 0.424 m
}

TEST(Safety, JointLimits) {
  const ArmModel model = puma260();
  EXPECT_TRUE(check_joint_limits(model, joints_from_degrees(0, 45, -180, 0, 0, 0)).ok());
  const CheckResult j3 = check_joint_limits(model, joints_from_degrees(0, 45, 50, 0, 0, 0));
  EXPECT_FALSE(j3.ok());
  EXPECT_TRUE(contains(j3.reason, "joint 3")) << j3.reason;
  JointVector nan_joints = JointVector::Zero();
  nan_joints[4] = std::nan("");
  EXPECT_FALSE(check_joint_limits(model, nan_joints).ok());
}

TEST(Safety, TableClearance) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  EXPECT_TRUE(check_table_clearance(model, safety, home.q).ok());
  EXPECT_TRUE(check_configuration(model, safety, home.q).ok());

  const IkResult low = nearest_inverse_kinematics(
      model, tool_down_pose({0.25, 0.0, safety.table_z + 0.002}, 0.0), home.q);
  ASSERT_TRUE(low.ok()) << low.reason;
  const CheckResult too_low = check_table_clearance(model, safety, low.q);
  EXPECT_FALSE(too_low.ok());
  EXPECT_TRUE(contains(too_low.reason, "tool point")) << too_low.reason;
  EXPECT_FALSE(check_configuration(model, safety, low.q).ok());
}

TEST(Safety, ConfigurationOutsideTheRingIsRefusedUnlessTheRingIsLifted) {
  const ArmModel model = puma260();
  SafetyConfig safety;
  const IkResult far = nearest_inverse_kinematics(
      model, tool_down_pose({0.38, 0.0, safety.table_z + 0.30}, 0.0), JointVector::Zero());
  ASSERT_TRUE(far.ok()) << far.reason;
  EXPECT_TRUE(contains(check_configuration(model, safety, far.q).reason, "ring"));
  safety.enforce_ring = false;
  EXPECT_TRUE(check_configuration(model, safety, far.q).ok());
}

TEST(Safety, JointPathBetweenSafeEndsCanDipBelowTheTable) {
  // Both ends 20 mm above the table, but the straight joint-space line between a near and a far
  // point sags under it: only dense sampling sees that.
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const IkResult near = safe_inverse_kinematics(
      model, safety, tool_down_pose({0.18, 0.0, safety.table_z + 0.02}, 0.0), home.q);
  const IkResult far = safe_inverse_kinematics(
      model, safety, tool_down_pose({0.34, 0.0, safety.table_z + 0.02}, 0.0), near.q);
  ASSERT_TRUE(near.ok()) << near.reason;
  ASSERT_TRUE(far.ok()) << far.reason;
  const CheckResult path = check_joint_path(model, safety, near.q, far.q);
  EXPECT_FALSE(path.ok());
  EXPECT_TRUE(contains(path.reason, "table")) << path.reason;
  // Going up first and down again is safe.
  const IkResult above_near = safe_inverse_kinematics(
      model, safety, tool_down_pose({0.18, 0.0, safety.table_z + 0.32}, 0.0), near.q);
  ASSERT_TRUE(above_near.ok()) << above_near.reason;
  EXPECT_TRUE(check_joint_path(model, safety, home.q, above_near.q).ok());
}

TEST(Safety, RefusesNonsenseConfig) {
  SafetyConfig safety;
  safety.ring_outer = 0.1;  // smaller than ring_inner
  EXPECT_THROW(validate(safety), std::invalid_argument);
  safety = SafetyConfig{};
  safety.tool_radius = -0.01;
  EXPECT_THROW(validate(safety), std::invalid_argument);
}

TEST(SegmentDistance, KnownGeometry) {
  using V = Eigen::Vector3d;
  EXPECT_NEAR(segment_distance(V(0, 0, 0), V(1, 0, 0), V(0.5, -1, 2), V(0.5, 1, 2)), 2.0, 1e-12);  // crossing
  EXPECT_NEAR(segment_distance(V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), V(1, 1, 0)), 1.0, 1e-12);       // parallel
  EXPECT_NEAR(segment_distance(V(0, 0, 0), V(1, 0, 0), V(3, 4, 0), V(5, 4, 0)), std::hypot(2, 4), 1e-12);  // ends
  EXPECT_NEAR(segment_distance(V(0, 0, 0), V(1, 0, 0), V(0.3, 0.2, 0), V(0.3, 0.2, 0)), 0.2, 1e-12);  // a point
  EXPECT_NEAR(segment_distance(V(1, 1, 1), V(1, 1, 1), V(1, 1, 4), V(1, 1, 4)), 3.0, 1e-12);  // two points
  EXPECT_NEAR(segment_distance(V(0, 0, 0), V(2, 2, 0), V(0, 2, 0), V(2, 0, 0)), 0.0, 1e-12);  // intersecting
}

TEST(Safety, SelfCollisionOfTheToolWithThePedestalOrTheUpperArm) {
  const ArmModel model = puma260();
  SafetyConfig safety;
  // Upper arm level, forearm folded back and down past the pedestal, wrist bent: the tool points
  // into the column the arm stands on...
  const CheckResult pedestal = check_self_collision(model, safety, joints_from_degrees(0, 0, -215, 90, -90, 0));
  EXPECT_FALSE(pedestal.ok());
  EXPECT_TRUE(contains(pedestal.reason, "tool") && contains(pedestal.reason, "pedestal")) << pedestal.reason;
  // ...or, turned the other way, back up at the upper arm.
  const CheckResult upper_arm = check_self_collision(model, safety, joints_from_degrees(0, 0, -225, 0, -90, 0));
  EXPECT_FALSE(upper_arm.ok());
  EXPECT_TRUE(contains(upper_arm.reason, "upper arm")) << upper_arm.reason;
  EXPECT_EQ(check_configuration(model, safety, joints_from_degrees(0, 0, -225, 0, -90, 0)).reason, upper_arm.reason);
  // The capsules are where the kinematics put the links.
  const ArmCapsules c = arm_capsules(model, safety, joints_from_degrees(0, 0, -225, 0, -90, 0));
  const ArmPoints points = arm_points(model, joints_from_degrees(0, 0, -225, 0, -90, 0));
  EXPECT_TRUE(c.tool.a.isApprox(points.wrist) && c.tool.b.isApprox(points.tool));
  EXPECT_TRUE(c.forearm.b.isApprox(points.wrist));
  EXPECT_NEAR((c.upper_arm.b - c.upper_arm.a).norm(), 0.2032, 1e-9);  // a2
  EXPECT_NEAR((c.forearm.b - c.forearm.a).norm(), 0.2032, 1e-9);      // d4
  // Stretched out, straight up, and the home pose are clear of themselves.
  EXPECT_TRUE(check_self_collision(model, safety, joints_from_degrees(0, 0, -90, 0, 0, 0)).ok());
  EXPECT_TRUE(check_self_collision(model, safety, joints_from_degrees(0, 90, -90, 0, 0, 0)).ok());
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  EXPECT_TRUE(check_self_collision(model, safety, home.q).ok());
  // Switched off, nothing is refused for self-collision.
  safety.check_self_collision = false;
  EXPECT_TRUE(check_self_collision(model, safety, joints_from_degrees(0, 0, -215, 90, -90, 0)).ok());
}

TEST(Safety, TheLinksGapToAStandingObjectIsMeasuredAlongTheWholePath) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  // At home the tool points straight down: an object under it is nearest the tool's tip.
  const Eigen::Vector3d tool = forward_kinematics(model, home.q).translation();
  const StandingObject under{Eigen::Vector3d(tool.x(), tool.y(), 0), 0.04, 0.10};
  const double expected = tool.z() - (safety.table_z + under.height) - safety.tool_radius - under.radius;
  EXPECT_NEAR(link_gap_to_standing_object(model, safety, under, home.q), expected, 1e-9);
  // Taller than the tool point is high: overlapping.
  StandingObject tall = under;
  tall.height = tool.z() - safety.table_z + 0.01;
  EXPECT_LT(link_gap_to_standing_object(model, safety, tall, home.q), 0.0);
  // One far from the arm is far from every link.
  const StandingObject far{Eigen::Vector3d(-0.4, 0.4, 0), 0.04, 0.25};
  EXPECT_GT(link_gap_to_standing_object(model, safety, far, home.q), 0.3);
  // Along a path, the least gap is found between the waypoints too: turning joint 1 by 90 deg
  // swings the tool into an object standing where the turn is half done, which neither end touches.
  JointVector turned = home.q;
  turned[0] += deg_to_rad(90.0);
  const JointVector middle = 0.5 * (home.q + turned);
  const Eigen::Vector3d halfway = forward_kinematics(model, middle).translation();
  const StandingObject swept{Eigen::Vector3d(halfway.x(), halfway.y(), 0), 0.04, tall.height};
  const double at_ends = std::min(link_gap_to_standing_object(model, safety, swept, home.q),
                                  link_gap_to_standing_object(model, safety, swept, turned));
  const double along = least_link_gap_along(model, safety, swept, {home.q, turned});
  EXPECT_NEAR(along, link_gap_to_standing_object(model, safety, swept, middle), 5e-3);  // samples 1 deg apart: 4 mm at the tool
  EXPECT_LT(along, 0.0);
  EXPECT_GT(at_ends, 0.0);
  EXPECT_EQ(least_link_gap_along(model, safety, swept, {}), std::numeric_limits<double>::infinity());
  EXPECT_NEAR(least_link_gap_along(model, safety, swept, {turned}), link_gap_to_standing_object(model, safety, swept, turned), 1e-12);
}

TEST(Safety, JointPathBetweenSelfCollisionFreeEndsCanFoldTheToolIntoTheArm) {
  // Turning joint 4 through 270 deg with the wrist bent back sweeps the tool past the upper arm:
  // both ends are clear, the middle is not.
  const ArmModel model = puma260();
  SafetyConfig safety;
  safety.enforce_ring = false;  // folded poses lie inside the ring: look at self-collision only
  const JointVector from = joints_from_degrees(0, 0, -215, -100, -90, 0);
  const JointVector to = joints_from_degrees(0, 0, -215, 170, -90, 0);
  ASSERT_TRUE(check_configuration(model, safety, from).ok()) << check_configuration(model, safety, from).reason;
  ASSERT_TRUE(check_configuration(model, safety, to).ok()) << check_configuration(model, safety, to).reason;
  const CheckResult path = check_joint_path(model, safety, from, to);
  EXPECT_FALSE(path.ok());
  EXPECT_TRUE(contains(path.reason, "self-collision")) << path.reason;
}

TEST(Safety, NudgesAndGraspsAcrossTheRingAreClearOfThemselves) {
  // The nudges and grasps the system plans are checked with self-collision on (check_joint_path):
  // across the workspace ring, the check refuses none of them (each plans exactly as it does with
  // the check off), and most of them plan.
  const ArmModel model = puma260();
  const SafetyConfig safety;
  SafetyConfig unchecked = safety;
  unchecked.check_self_collision = false;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const NudgeParams params = nudge_params_for_objects(0.09, 0.03, 0.25);
  int nudges = 0, grasps = 0;
  for (double radius : {0.20, 0.25, 0.30}) {
    for (double bearing_deg : {-60.0, -30.0, 0.0, 30.0, 60.0}) {
      const double b = deg_to_rad(bearing_deg);
      const Eigen::Vector3d target(radius * std::cos(b), radius * std::sin(b), safety.table_z);
      const Eigen::Vector3d direction(-std::sin(b), std::cos(b), 0.0);  // across the ring
      const NudgePlan nudge = plan_nudge(model, safety, target, direction, params, home.q);
      EXPECT_EQ(nudge.reason, plan_nudge(model, unchecked, target, direction, params, home.q).reason);
      const GraspPlan grasp = plan_grasp(model, safety, target, 0.08, b, GraspParams{}, home.q);
      EXPECT_EQ(grasp.reason, plan_grasp(model, unchecked, target, 0.08, b, GraspParams{}, home.q).reason);
      nudges += nudge.ok();
      grasps += grasp.ok();
    }
  }
  EXPECT_EQ(nudges, 15);
  EXPECT_GE(grasps, 10);  // near the ring's inner edge the descent runs into joint 3's limit
}

// ---------------------------------------------------------------- nudge and other motions

TEST(Nudge, TargetInsideTheRingGivesASafeThesisMotion) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const NudgeParams params = nudge_params_for_objects(0.09, 0.03, 0.25);
  EXPECT_NEAR(params.start_distance, 0.11, 1e-12);  // largest radius + 20 mm clearance
  EXPECT_NEAR(params.stop_distance, 0.02, 1e-12);   // 10 mm past the smallest object's surface

  const Eigen::Vector3d target(0.25, 0.0, safety.table_z);
  const Eigen::Vector3d direction(0.0, 1.0, 0.0);
  const NudgePlan plan = plan_nudge(model, safety, target, direction, params, home.q);
  ASSERT_TRUE(plan.ok()) << plan.reason;

  // P0 -> P1 -> P2 -> P1 -> P0 with the documented geometry.
  const Eigen::Vector3d p0 = plan.poses[0].translation();
  const Eigen::Vector3d p1 = plan.poses[1].translation();
  const Eigen::Vector3d p2 = plan.poses[2].translation();
  EXPECT_LT((p0 - Eigen::Vector3d(0.25, -0.11, safety.table_z + params.approach_height)).norm(),
            1e-12);
  EXPECT_LT((p1 - Eigen::Vector3d(0.25, -0.11, safety.table_z + params.push_height)).norm(), 1e-12);
  EXPECT_LT((p2 - Eigen::Vector3d(0.25, -0.02, safety.table_z + params.push_height)).norm(), 1e-12);
  EXPECT_LT(position_error(plan.poses[3], plan.poses[1]), 1e-12);
  EXPECT_LT(position_error(plan.poses[4], plan.poses[0]), 1e-12);
  for (int k = 0; k < 5; ++k) {
    const Eigen::Isometry3d reached = forward_kinematics(model, plan.key_joints[k]);
    EXPECT_LT(position_error(reached, plan.poses[k]), kPoseTolerance) << "P" << k;
    EXPECT_LT(rotation_error(reached, plan.poses[k]), kPoseTolerance) << "P" << k;
  }

  // The path starts and ends at P0, is safe, and never carries the tool past the symmetry axis.
  ASSERT_GE(plan.waypoints.size(), 5u);
  EXPECT_EQ(plan.waypoints.front(), plan.key_joints[0]);
  EXPECT_EQ(plan.waypoints.back(), plan.key_joints[0]);
  EXPECT_TRUE(check_joint_path(model, safety, plan.waypoints).ok());
  for (const JointVector& q : plan.waypoints) {
    const Eigen::Vector3d tool = forward_kinematics(model, q).translation();
    EXPECT_LE((tool - target).dot(direction), -params.stop_distance + 1e-9);
    EXPECT_GE(tool.z(), safety.table_z + params.push_height - 1e-9);
  }

  // Executable as the thesis did: linear joint interpolation at the speed limits.
  const LinearTrajectory trajectory = LinearTrajectory::at_speed(plan.waypoints, model.max_speed);
  EXPECT_GT(trajectory.duration(), 0.0);
}

TEST(Nudge, TheToolLeansSoThatTheWristTrailsThePadPastATallObject) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const Eigen::Vector3d target(0.26, 0.045, safety.table_z), direction(0.0, -1.0, 0.0);
  NudgeParams tall;  // 0.25 m: the straight-down tool's wrist, 0.16 m up, would strike it
  const NudgePlan leaned = plan_nudge(model, safety, target, direction, tall, home.q);
  ASSERT_TRUE(leaned.ok()) << leaned.reason;
  EXPECT_NEAR(leaned.tilt, tall.tool_tilt, 1e-12);
  for (const JointVector& q : leaned.waypoints) {
    EXPECT_GE(link_gap_to_pushed_object(model, safety, tall, target, leaned.direction, q), tall.link_clearance);
  }
  // The pad still faces the push: the tool's x axis keeps its horizontal part along it.
  for (const Eigen::Isometry3d& pose : leaned.poses) {
    const Eigen::Vector3d x = pose.linear().col(0);
    EXPECT_NEAR(Eigen::Vector2d(x.x(), x.y()).normalized().dot(direction.head<2>()), 1.0, 1e-9);
    EXPECT_NEAR(pose.linear().col(2).dot(-Eigen::Vector3d::UnitZ()), std::cos(tall.tool_tilt), 1e-9);
  }
  // A short object leaves the thesis' straight-down tool; no check at all, too.
  NudgeParams short_object = tall;
  short_object.object_height = 0.08;
  const NudgePlan straight = plan_nudge(model, safety, target, direction, short_object, home.q);
  ASSERT_TRUE(straight.ok()) << straight.reason;
  EXPECT_EQ(straight.tilt, 0.0);
  EXPECT_LT(rotation_error(straight.poses[1], tool_down_pose(straight.poses[1].translation(), -kPi / 2)), 1e-9);
  // With leaning forbidden, the tall object is refused with the reason.
  NudgeParams no_lean = tall;
  no_lean.tool_tilt = 0;
  const NudgePlan refused = plan_nudge(model, safety, target, direction, no_lean, home.q);
  EXPECT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.reason, "forearm or wrist")) << refused.reason;
  NudgeParams bad = tall;
  bad.tool_tilt = deg_to_rad(70);
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

TEST(Nudge, AcrossTheCameraViewPushesPerpendicularToTheRay) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const Eigen::Vector3d camera(0.7, 0.1, 0.2);
  const Eigen::Vector3d target(0.24, 0.05, safety.table_z);
  const NudgePlan plan =
      plan_nudge_across_view(model, safety, target, camera, NudgeParams{}, home.q);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  const Eigen::Vector3d ray = target - camera;
  EXPECT_NEAR(plan.direction.dot(Eigen::Vector3d(ray.x(), ray.y(), 0).normalized()), 0.0, 1e-12);
  EXPECT_NEAR(plan.direction.z(), 0.0, 1e-12);
}

TEST(Nudge, RefusesTargetsOutsideTheRingAndBadParameters) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const NudgePlan far = plan_nudge(model, safety, {0.45, 0.0, safety.table_z}, {0, 1, 0},
                                   NudgeParams{}, JointVector::Zero());
  EXPECT_FALSE(far.ok());
  EXPECT_TRUE(contains(far.reason, "ring")) << far.reason;
  const NudgePlan vertical = plan_nudge(model, safety, {0.25, 0.0, safety.table_z}, {0, 0, 1},
                                        NudgeParams{}, JointVector::Zero());
  EXPECT_FALSE(vertical.ok());
  NudgeParams crossing;
  crossing.stop_distance = -0.01;  // P2 beyond the symmetry axis
  EXPECT_THROW(validate(crossing), std::invalid_argument);
  EXPECT_THROW(nudge_params_for_objects(0.09, 0.005, 0.25), std::invalid_argument);
}

TEST(Nudge, UnreachableTargetGivesAReasonNotACrash) {
  // Near the inner edge of the ring the descent folds the elbow past joint 3's limit.
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok());
  const NudgePlan plan = plan_nudge(model, safety, {0.16, 0.0, safety.table_z}, {1, 0, 0},
                                    NudgeParams{}, home.q);
  EXPECT_FALSE(plan.ok());
  EXPECT_FALSE(plan.reason.empty());
}

TEST(CartesianLine, StaysOnTheLine) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok());
  const Eigen::Isometry3d from = forward_kinematics(model, home.q);
  Eigen::Isometry3d to = from;
  to.translation() += Eigen::Vector3d(0.0, 0.05, -0.1);
  const JointPath path = cartesian_line(model, from, to, home.q, 0.005);
  ASSERT_TRUE(path.ok()) << path.reason;
  EXPECT_EQ(path.waypoints.size(), 24u);  // ceil(0.1118 / 0.005) steps + the start
  const Eigen::Vector3d direction = (to.translation() - from.translation()).normalized();
  for (const JointVector& q : path.waypoints) {
    const Eigen::Vector3d offset = forward_kinematics(model, q).translation() - from.translation();
    EXPECT_LT((offset - offset.dot(direction) * direction).norm(), 1e-9);
  }
  EXPECT_LT(position_error(forward_kinematics(model, path.waypoints.back()), to), kPoseTolerance);
}

TEST(Grasp, DescendsAndLiftsVertically) {
  const ArmModel model = puma260();
  const SafetyConfig safety;
  const IkResult home = home_configuration(model, safety);
  ASSERT_TRUE(home.ok());
  const Eigen::Vector3d axis_on_table(0.26, 0.04, safety.table_z);
  const GraspPlan plan =
      plan_grasp(model, safety, axis_on_table, 0.08, deg_to_rad(30), GraspParams{}, home.q);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  ASSERT_FALSE(plan.descend.empty());
  ASSERT_FALSE(plan.lift.empty());
  const Eigen::Vector3d grasp_point = forward_kinematics(model, plan.descend.back()).translation();
  EXPECT_LT((grasp_point - Eigen::Vector3d(0.26, 0.04, safety.table_z + 0.08)).norm(), 1e-6);
  EXPECT_EQ(plan.lift.front(), plan.descend.back());
  for (const auto* path : {&plan.descend, &plan.lift}) {
    for (const JointVector& q : *path) {
      const Eigen::Vector3d p = forward_kinematics(model, q).translation();
      EXPECT_NEAR(p.x(), 0.26, 1e-6);
      EXPECT_NEAR(p.y(), 0.04, 1e-6);
    }
  }
}

TEST(RotateWrist, TurnsJointSixWithinItsLimits) {
  const ArmModel model = puma260();
  JointVector q = joints_from_degrees(0, 45, -180, 0, -45, 0);
  // Sec. 7.2: twelve views, 30 degrees apart, centred on the start.
  q[5] = deg_to_rad(-165);
  for (int view = 0; view < 11; ++view) {
    const IkResult turned = rotate_wrist(model, q, deg_to_rad(30));
    ASSERT_TRUE(turned.ok()) << turned.reason;
    EXPECT_NEAR(turned.q[5] - q[5], deg_to_rad(30), 1e-12);
    q = turned.q;
  }
  q[5] = deg_to_rad(250);
  const IkResult past = rotate_wrist(model, q, deg_to_rad(30));
  EXPECT_FALSE(past.ok());
  EXPECT_TRUE(contains(past.reason, "joint 6")) << past.reason;
  EXPECT_EQ(past.q, q);
}

// ---------------------------------------------------------------- driver

TEST(FakeDriver, FollowsTimedTargetsOnItsOwnClock) {
  const ArmModel model = puma260();
  const JointVector start = joints_from_degrees(0, 45, -180, 0, -45, 0);
  FakeDriver driver(model.limits, start);
  const JointVector goal = joints_from_degrees(20, 60, -170, 10, -60, 30);
  const TrapezoidalMove move(start, goal, model.max_speed, model.max_acceleration);
  std::vector<TimedJoints> targets = sample_trajectory(move, 0.02);
  targets.erase(targets.begin());  // the driver starts from where it is
  ASSERT_EQ(driver.send_joint_targets(targets), "");
  EXPECT_EQ(driver.accepted_commands(), 1);

  driver.advance(targets[5].time);
  JointState state = driver.read_joint_state();
  EXPECT_TRUE(state.moving);
  EXPECT_LT((state.position - targets[5].q).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(state.velocity.norm(), 0.0);

  driver.advance(move.duration());
  state = driver.read_joint_state();
  EXPECT_FALSE(state.moving);
  EXPECT_EQ(state.position, goal);
}

TEST(FakeDriver, StopHoldsAndBadTargetsAreRefused) {
  const ArmModel model = puma260();
  const JointVector start = joints_from_degrees(0, 45, -180, 0, -45, 0);
  FakeDriver driver(model.limits, start);
  const JointVector goal = joints_from_degrees(40, 45, -180, 0, -45, 0);
  ASSERT_EQ(driver.send_joint_targets({{2.0, goal}}), "");
  driver.advance(1.0);
  driver.stop();
  const JointVector held = driver.read_joint_state().position;
  EXPECT_NEAR(held[0], deg_to_rad(20), 1e-12);
  driver.advance(5.0);
  EXPECT_EQ(driver.read_joint_state().position, held);
  EXPECT_FALSE(driver.read_joint_state().moving);
  EXPECT_EQ(driver.stop_count(), 1);

  const JointVector beyond = joints_from_degrees(170, 45, -180, 0, -45, 0);
  EXPECT_NE(driver.send_joint_targets({{1.0, beyond}}), "");
  EXPECT_NE(driver.send_joint_targets({}), "");
  EXPECT_NE(driver.send_joint_targets({{1.0, goal}, {0.5, goal}}), "");
  EXPECT_EQ(driver.read_joint_state().position, held);  // nothing moved

  ArmDriver& generic = driver;
  EXPECT_EQ(generic.close_gripper(), "");
  EXPECT_EQ(generic.read_joint_state().gripper_opening, 0.0);
  EXPECT_EQ(generic.open_gripper(), "");
  EXPECT_EQ(generic.read_joint_state().gripper_opening, FakeDriver::kGripperOpen);
}
