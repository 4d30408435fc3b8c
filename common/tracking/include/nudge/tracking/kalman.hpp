#pragma once
// Kalman filter for one symmetry line (Li 2008, sec. 5.2.4, eq. 5.1).
//
// State x = [R, theta, R', theta', R'', theta''] (constant acceleration, time step = 1 frame).
// Units: R in pixels, theta in DEGREES, derivatives per frame (per frame^2). Degrees because the
// thesis gives its covariances in deg^2 (measurement 9 px^2, 9 deg^2); conversion to radians happens
// only at the library boundary (TrackState, messages).
//
// Theta wrap-around: (R, theta) and (-R, theta +- 180 deg) are the same line. The filter keeps its
// theta in (-90, 90]; a measurement is compared in whichever of its two forms lies nearer the
// prediction, and when the state crosses +-90 it is flipped to the other form (R and its
// derivatives negated, the covariance transformed to match), so tracking continues smoothly.
#include <Eigen/Core>

#include <array>

namespace nudge::tracking {

using KalmanState = Eigen::Matrix<double, 6, 1>;
using KalmanCovariance = Eigen::Matrix<double, 6, 6>;

struct KalmanParams {
  double measurement_var_r = 9.0;      // px^2 (thesis)
  double measurement_var_theta = 9.0;  // deg^2 (thesis)
  // Process noise diagonal, per frame, in state order [R, theta, R', theta', R'', theta''].
  // The thesis' list is garbled ("1, 0, 1, 10, 1, 10, 1"); its likely reading (1, 10, 1, 10, 1, 10)
  // was the starting point. With those values the predicted sigma is ~9 px / 9 deg, so the 9.21
  // gate spans ~+-30 px / +-30 deg and the filter hardly smooths (error ratio 0.93). These tuned values (docs/tracking.md) keep the gate at
  // ~+-15 px / deg, smooth noise to 0.75 of the raw error, and still gate a 10 px/frame object that
  // stops dead (normalised innovation <= 4).
  std::array<double, 6> process_noise = {1.0, 1.0, 0.5, 0.5, 0.05, 0.05};
  // Covariance of a fresh state: the first measurement's noise for R and theta, a deliberately
  // crude prior for the unknown velocities (sigma 20 px/frame, 10 deg/frame) and accelerations
  // (5 px/frame^2, 2 deg/frame^2). A tight velocity prior makes the automatic start prefer
  // associations that stand still, i.e. chains of wrong lines, over a fast-moving object.
  std::array<double, 6> initial_variance = {9.0, 9.0, 400.0, 100.0, 25.0, 4.0};
  double gate = 9.21;                  // chi^2, 2 DOF, P = 0.01 (thesis)
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const KalmanParams& params);

struct LineMeasurement {
  double r = 0;          // px
  double theta_deg = 0;  // degrees
  double votes = 0;      // the detector's accumulator value (support); 0 when unknown
};

// theta into (-90, 90], negating r for every 180 degrees moved.
LineMeasurement normalise(LineMeasurement line);
// The form of `line` ((R, theta) or (-R, theta +- 180)) whose theta is nearest theta_ref_deg.
LineMeasurement align_to(const LineMeasurement& line, double theta_ref_deg);

class LineKalman {
 public:
  explicit LineKalman(KalmanParams params = {});

  const KalmanParams& params() const { return params_; }
  void initialise(const LineMeasurement& first);
  // A state known to stand still (a track started at a line known from elsewhere, before the
  // object moves): velocities and accelerations zero with a small variance (sigma 2 px / 1 deg per
  // frame, 1 px / 0.5 deg per frame^2), so the first frames' gate stays narrow about the line.
  void initialise_at_rest(const LineMeasurement& first);
  void predict();
  // The object is seen to stand still (no motion where it is): velocities and accelerations are
  // set to zero and decoupled from R and theta, whose estimate and covariance stay as they are.
  // Used instead of predict() so that a track does not coast on after the object stopped.
  void hold();
  // The object is seen at rest (its own line measured where it stopped): hold(), and the velocity
  // and acceleration variances drop to initialise_at_rest's (never grow), so that frames predicted
  // next keep a narrow gate about the resting object instead of one sized for its old motion.
  void rest();
  // Normalised innovation squared (the thesis' "validation gate error") of a measurement.
  double gate_error(const LineMeasurement& measured) const;
  bool in_gate(double gate_error) const { return gate_error <= params_.gate; }
  void update(const LineMeasurement& measured);

  const KalmanState& state() const { return x_; }
  const KalmanCovariance& covariance() const { return p_; }
  LineMeasurement line() const { return {x_(0), x_(1)}; }
  double theta_sigma_deg() const;
  Eigen::Matrix2d line_covariance() const { return p_.topLeftCorner<2, 2>(); }  // (px, deg)

  static const Eigen::Matrix<double, 6, 6>& transition();  // A of eq. 5.1

 private:
  Eigen::Vector2d innovation(const LineMeasurement& measured) const;
  Eigen::Matrix2d innovation_covariance() const;
  void keep_theta_in_range();

  KalmanParams params_;
  KalmanState x_ = KalmanState::Zero();
  KalmanCovariance p_ = KalmanCovariance::Identity();
};

// Orientation limits for the detector: the predicted theta +- k sigma (thesis: k = 3), in degrees
// within [-90, 90]; min > max means the range wraps across +-90 (as nudge::symmetry::Params).
struct AngleLimits {
  double min_deg = -90, max_deg = 90;
  bool full() const { return min_deg <= -90 && max_deg >= 90; }
};
AngleLimits angle_limits(double theta_deg, double sigma_deg, double num_sigma, double min_half_width_deg);

}  // namespace nudge::tracking
