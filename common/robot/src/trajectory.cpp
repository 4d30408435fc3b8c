#include "nudge/robot/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nudge::robot {
namespace {

void require_positive_limits(const JointVector& limits, const char* what) {
  for (int j = 0; j < kNumJoints; ++j) {
    if (!std::isfinite(limits[j]) || limits[j] <= 0) {
      throw std::invalid_argument(std::string(what) + " of joint " + std::to_string(j + 1) +
                                  " must be finite and positive, got " +
                                  std::to_string(limits[j]));
    }
  }
}

}  // namespace

LinearTrajectory::LinearTrajectory(std::vector<TimedJoints> waypoints)
    : waypoints_(std::move(waypoints)) {
  if (waypoints_.empty()) throw std::invalid_argument("linear trajectory: no waypoints");
  if (waypoints_.front().time != 0.0) {
    throw std::invalid_argument("linear trajectory: the first waypoint must be at time 0");
  }
  for (size_t i = 0; i < waypoints_.size(); ++i) {
    const TimedJoints& w = waypoints_[i];
    if (!std::isfinite(w.time) || !w.q.allFinite()) {
      throw std::invalid_argument("linear trajectory: waypoint " + std::to_string(i) +
                                  " has non-finite values");
    }
    if (i > 0 && !(w.time > waypoints_[i - 1].time)) {
      throw std::invalid_argument("linear trajectory: waypoint " + std::to_string(i) +
                                  " is not later than the one before");
    }
  }
}

LinearTrajectory LinearTrajectory::at_speed(const std::vector<JointVector>& waypoints,
                                            const JointVector& max_speed, double speed_scale) {
  require_positive_limits(max_speed, "speed limit");
  if (!std::isfinite(speed_scale) || speed_scale <= 0) {
    throw std::invalid_argument("linear trajectory: speed scale must be positive, got " +
                                std::to_string(speed_scale));
  }
  if (waypoints.empty()) throw std::invalid_argument("linear trajectory: no waypoints");
  const JointVector speed = max_speed * speed_scale;
  std::vector<TimedJoints> timed{{0.0, waypoints.front()}};
  for (size_t i = 1; i < waypoints.size(); ++i) {
    const JointVector travel = (waypoints[i] - timed.back().q).cwiseAbs();
    const double segment_time = travel.cwiseQuotient(speed).maxCoeff();
    if (segment_time <= 0) continue;  // a repeated waypoint adds nothing
    timed.push_back({timed.back().time + segment_time, waypoints[i]});
  }
  return LinearTrajectory(std::move(timed));
}

double LinearTrajectory::duration() const { return waypoints_.back().time; }

size_t LinearTrajectory::segment_at(double t) const {
  // First waypoint strictly later than t ends the segment.
  const auto later = std::upper_bound(
      waypoints_.begin(), waypoints_.end(), t,
      [](double time, const TimedJoints& w) { return time < w.time; });
  const size_t end = static_cast<size_t>(later - waypoints_.begin());
  return std::min(end, waypoints_.size() - 1) - 1;
}

JointVector LinearTrajectory::position(double t) const {
  if (waypoints_.size() == 1 || t <= 0) return waypoints_.front().q;
  if (t >= duration()) return waypoints_.back().q;
  const size_t i = segment_at(t);
  const TimedJoints& a = waypoints_[i];
  const TimedJoints& b = waypoints_[i + 1];
  const double fraction = (t - a.time) / (b.time - a.time);
  return a.q + fraction * (b.q - a.q);
}

JointVector LinearTrajectory::velocity(double t) const {
  if (waypoints_.size() == 1 || t < 0 || t >= duration()) return JointVector::Zero();
  const size_t i = segment_at(t);
  const TimedJoints& a = waypoints_[i];
  const TimedJoints& b = waypoints_[i + 1];
  return (b.q - a.q) / (b.time - a.time);
}

TrapezoidalMove::TrapezoidalMove(const JointVector& start, const JointVector& goal,
                                 const JointVector& max_speed, const JointVector& max_acceleration)
    : start_(start), goal_(goal), delta_(goal - start) {
  require_positive_limits(max_speed, "speed limit");
  require_positive_limits(max_acceleration, "acceleration limit");
  if (!start.allFinite() || !goal.allFinite()) {
    throw std::invalid_argument("trapezoidal move: start or goal has non-finite joint values");
  }
  // Limits on the shared path parameter s in [0, 1]: the tightest joint decides.
  double speed = std::numeric_limits<double>::infinity();
  double accel = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kNumJoints; ++j) {
    const double distance = std::fabs(delta_[j]);
    if (distance == 0) continue;
    speed = std::min(speed, max_speed[j] / distance);
    accel = std::min(accel, max_acceleration[j] / distance);
  }
  if (!std::isfinite(speed)) return;  // start == goal: a zero-length move
  path_accel_ = accel;
  if (speed * speed / accel >= 1.0) {
    // Triangular: the move ends before the speed limit is reached.
    peak_speed_ = std::sqrt(accel);
    accel_time_ = peak_speed_ / accel;
    duration_ = 2.0 * accel_time_;
  } else {
    peak_speed_ = speed;
    accel_time_ = speed / accel;
    const double cruise_distance = 1.0 - speed * accel_time_;  // the two ramps cover speed * ta
    duration_ = 2.0 * accel_time_ + cruise_distance / speed;
  }
}

double TrapezoidalMove::path_position(double t) const {
  if (t <= 0) return 0;
  if (t >= duration_) return 1;
  if (t < accel_time_) return 0.5 * path_accel_ * t * t;
  const double remaining = duration_ - t;
  if (remaining < accel_time_) return 1.0 - 0.5 * path_accel_ * remaining * remaining;
  return 0.5 * path_accel_ * accel_time_ * accel_time_ + peak_speed_ * (t - accel_time_);
}

double TrapezoidalMove::path_velocity(double t) const {
  if (t <= 0 || t >= duration_) return 0;
  if (t < accel_time_) return path_accel_ * t;
  const double remaining = duration_ - t;
  if (remaining < accel_time_) return path_accel_ * remaining;
  return peak_speed_;
}

double TrapezoidalMove::path_acceleration(double t) const {
  if (t < 0 || t > duration_) return 0;
  if (t < accel_time_) return path_accel_;
  if (duration_ - t < accel_time_) return -path_accel_;
  return 0;
}

JointVector TrapezoidalMove::position(double t) const {
  if (t >= duration_) return goal_;  // exactly the goal, no rounding from start + delta
  return start_ + path_position(t) * delta_;
}

JointVector TrapezoidalMove::velocity(double t) const { return path_velocity(t) * delta_; }

JointVector TrapezoidalMove::acceleration(double t) const {
  return path_acceleration(t) * delta_;
}

std::vector<TimedJoints> sample_trajectory(const JointTrajectory& trajectory, double dt) {
  if (!std::isfinite(dt) || dt <= 0) {
    throw std::invalid_argument("sample_trajectory: dt must be positive, got " +
                                std::to_string(dt));
  }
  const double duration = trajectory.duration();
  std::vector<TimedJoints> samples;
  const auto steps = static_cast<long>(std::ceil(duration / dt - 1e-9));
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    samples.push_back({t, trajectory.position(t)});
  }
  samples.push_back({duration, trajectory.position(duration)});
  return samples;
}

}  // namespace nudge::robot
