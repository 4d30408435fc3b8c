#include "nudge/bus/axes_convert.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nudge::bus {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void copy3(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v(i);
}

Eigen::Vector3d vector3(const double in[3]) { return {in[0], in[1], in[2]}; }

}  // namespace

axis3d_t to_message(const geometry::PairedAxis& a, const geometry::TableFrame* table) {
  axis3d_t m{};
  m.left_index = a.left_index;
  m.right_index = a.right_index;
  if (!table) {
    copy3(a.axis.a, m.point_a);
    copy3(a.axis.b, m.point_b);
    copy3(Eigen::Vector3d::Constant(kNaN), m.table_point);
    m.angle_to_normal = kNaN;
    return m;
  }
  copy3(table->to_table(a.axis.a), m.point_a);
  copy3(table->to_table(a.axis.b), m.point_b);
  copy3(a.hit ? table->to_table(a.hit->point) : Eigen::Vector3d::Constant(kNaN), m.table_point);
  m.angle_to_normal = a.hit ? a.hit->tilt_deg * M_PI / 180.0 : kNaN;
  return m;
}

axes_t to_message(const geometry::PairingResult& result, int64_t utime, const geometry::TableFrame* table) {
  axes_t m;
  m.utime = utime;
  m.num_pairings = result.pairings;
  for (const geometry::PairedAxis& a : result.axes) m.axes.push_back(to_message(a, table));
  m.num_axes = static_cast<int32_t>(m.axes.size());
  return m;
}

geometry::PairedAxis from_message(const axis3d_t& m) {
  geometry::PairedAxis a;
  a.left_index = m.left_index;
  a.right_index = m.right_index;
  a.axis.a = vector3(m.point_a);
  a.axis.b = vector3(m.point_b);
  const Eigen::Vector3d table_point = vector3(m.table_point);
  if (table_point.allFinite()) a.hit = geometry::TableHit{table_point, m.angle_to_normal * 180.0 / M_PI, 0.0};
  return a;
}

geometry::PairingResult from_message(const axes_t& m) {
  if (m.num_axes != static_cast<int32_t>(m.axes.size()))
    throw std::invalid_argument("axes_t num_axes " + std::to_string(m.num_axes) + " disagrees with the " +
                                std::to_string(m.axes.size()) + " axes sent");
  geometry::PairingResult result;
  result.pairings = m.num_pairings;
  for (const axis3d_t& a : m.axes) result.axes.push_back(from_message(a));
  return result;
}

}  // namespace nudge::bus
