#include "nudge/tracking/kalman.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nudge::tracking {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}
bool positive_finite(double v) { return std::isfinite(v) && v > 0; }
}  // namespace

void validate(const KalmanParams& p) {
  require(positive_finite(p.measurement_var_r) && positive_finite(p.measurement_var_theta),
          "Kalman measurement variances must be finite and > 0");
  for (double q : p.process_noise) require(std::isfinite(q) && q >= 0, "Kalman process noise must be finite and >= 0");
  for (double v : p.initial_variance) require(positive_finite(v), "Kalman initial variances must be finite and > 0");
  require(positive_finite(p.gate), "Kalman validation gate must be finite and > 0");
}

LineMeasurement normalise(LineMeasurement line) {
  if (!std::isfinite(line.theta_deg) || !std::isfinite(line.r)) return line;
  const double turns = std::ceil((line.theta_deg - 90.0) / 180.0);  // half-turns to remove
  line.theta_deg -= 180.0 * turns;
  if (static_cast<long long>(turns) % 2 != 0) line.r = -line.r;
  return line;
}

LineMeasurement align_to(const LineMeasurement& line, double theta_ref_deg) {
  LineMeasurement out = line;
  const double turns = std::round((theta_ref_deg - line.theta_deg) / 180.0);
  if (!std::isfinite(turns)) return out;
  out.theta_deg += 180.0 * turns;
  if (static_cast<long long>(turns) % 2 != 0) out.r = -out.r;
  return out;
}

const Eigen::Matrix<double, 6, 6>& LineKalman::transition() {
  static const Eigen::Matrix<double, 6, 6> a = [] {
    Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Identity();
    m(0, 2) = m(1, 3) = m(2, 4) = m(3, 5) = 1.0;
    m(0, 4) = m(1, 5) = 0.5;
    return m;
  }();
  return a;
}

LineKalman::LineKalman(KalmanParams params) : params_(params) { validate(params_); }

void LineKalman::initialise(const LineMeasurement& first) {
  const LineMeasurement m = normalise(first);
  x_ = KalmanState::Zero();
  x_(0) = m.r;
  x_(1) = m.theta_deg;
  p_ = KalmanCovariance::Zero();
  for (int i = 0; i < 6; ++i) p_(i, i) = params_.initial_variance[i];
}

namespace {
constexpr std::array<double, 4> kAtRestVariance = {4.0, 1.0, 1.0, 0.25};  // R', theta', R'', theta''
}

void LineKalman::initialise_at_rest(const LineMeasurement& first) {
  initialise(first);
  for (int i = 0; i < 4; ++i) p_(i + 2, i + 2) = kAtRestVariance[i];
}

void LineKalman::rest() {
  hold();
  p_.bottomRightCorner<4, 4>() = p_.bottomRightCorner<4, 4>().diagonal().asDiagonal();
  for (int i = 0; i < 4; ++i) p_(i + 2, i + 2) = std::min(p_(i + 2, i + 2), kAtRestVariance[i]);
}

void LineKalman::predict() {
  const auto& a = transition();
  x_ = a * x_;
  p_ = a * p_ * a.transpose();
  for (int i = 0; i < 6; ++i) p_(i, i) += params_.process_noise[i];
  keep_theta_in_range();
}

void LineKalman::hold() {
  x_.tail<4>().setZero();
  p_.topRightCorner<2, 4>().setZero();
  p_.bottomLeftCorner<4, 2>().setZero();
}

Eigen::Vector2d LineKalman::innovation(const LineMeasurement& measured) const {
  const LineMeasurement m = align_to(measured, x_(1));
  return {m.r - x_(0), m.theta_deg - x_(1)};
}

Eigen::Matrix2d LineKalman::innovation_covariance() const {
  Eigen::Matrix2d s = p_.topLeftCorner<2, 2>();
  s(0, 0) += params_.measurement_var_r;
  s(1, 1) += params_.measurement_var_theta;
  return s;
}

double LineKalman::gate_error(const LineMeasurement& measured) const {
  const Eigen::Vector2d nu = innovation(measured);
  if (!nu.allFinite()) return std::numeric_limits<double>::infinity();
  return nu.dot(innovation_covariance().ldlt().solve(nu));
}

void LineKalman::update(const LineMeasurement& measured) {
  const Eigen::Vector2d nu = innovation(measured);
  if (!nu.allFinite()) return;  // a NaN measurement must never poison the state
  const Eigen::Matrix2d s = innovation_covariance();
  // K = P H' S^-1; H picks the first two states, so P H' is the first two columns of P.
  const Eigen::Matrix<double, 6, 2> k = p_.leftCols<2>() * s.inverse();
  x_ += k * nu;
  // Joseph form keeps P symmetric positive definite over thousands of frames.
  Eigen::Matrix<double, 6, 6> i_kh = Eigen::Matrix<double, 6, 6>::Identity();
  i_kh.leftCols<2>() -= k;
  Eigen::Matrix2d r = Eigen::Matrix2d::Zero();
  r(0, 0) = params_.measurement_var_r;
  r(1, 1) = params_.measurement_var_theta;
  p_ = i_kh * p_ * i_kh.transpose() + k * r * k.transpose();
  keep_theta_in_range();
}

double LineKalman::theta_sigma_deg() const { return std::sqrt(std::max(0.0, p_(1, 1))); }

void LineKalman::keep_theta_in_range() {
  if (!std::isfinite(x_(1))) return;
  const double normal_theta = normalise({0.0, x_(1)}).theta_deg;
  if (normal_theta == x_(1)) return;
  const long half_turns = std::lround((x_(1) - normal_theta) / 180.0);
  x_(1) = normal_theta;
  if (half_turns % 2 == 0) return;
  // (R, theta) -> (-R, theta - 180): R and its derivatives change sign, theta's do not.
  Eigen::Matrix<double, 6, 1> t;
  t << -1, 1, -1, 1, -1, 1;
  x_ = t.asDiagonal() * x_;
  p_ = t.asDiagonal() * p_ * t.asDiagonal();
}

AngleLimits angle_limits(double theta_deg, double sigma_deg, double num_sigma, double min_half_width_deg) {
  const double half = std::max(min_half_width_deg, num_sigma * sigma_deg);
  if (!std::isfinite(half) || !std::isfinite(theta_deg) || half >= 90.0) return {};
  const double centre = normalise({0.0, theta_deg}).theta_deg;
  auto wrap = [](double t) { return t > 90.0 ? t - 180.0 : (t < -90.0 ? t + 180.0 : t); };
  return {wrap(centre - half), wrap(centre + half)};
}

}  // namespace nudge::tracking
