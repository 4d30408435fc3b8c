// axes_t <-> nudge::geometry (nudge_bus_geometry).
#include <gtest/gtest.h>

#include <cmath>

#include "nudge/bus/axes_convert.hpp"

using namespace nudge;

namespace {

geometry::PairedAxis axis_with_hit() {
  geometry::PairedAxis a;
  a.left_index = 2;
  a.right_index = 5;
  a.axis.a = {0.1, -0.2, 0.9};
  a.axis.b = {0.1, 0.05, 0.95};
  a.hit = geometry::TableHit{{0.1, 0.5, 0.85}, 7.5, 0.9};  // on table_plane()
  return a;
}

// A table 0.5 m below the right camera (y down in the camera frame), seen from above.
geometry::Plane table_plane() {
  geometry::Plane p;
  p.normal = {0, -1, 0};
  p.offset = 0.5;
  return p;
}

}  // namespace

TEST(AxesConvert, CameraFrameAxesRoundTrip) {
  geometry::PairingResult result;
  result.pairings = 6;
  geometry::PairedAxis no_table = axis_with_hit();
  no_table.hit.reset();
  result.axes = {no_table, no_table};
  result.axes[1].left_index = 3;
  const axes_t msg = bus::to_message(result, 1234, nullptr);
  EXPECT_EQ(msg.utime, 1234);
  EXPECT_EQ(msg.num_pairings, 6);
  ASSERT_EQ(msg.num_axes, 2);
  EXPECT_TRUE(std::isnan(msg.axes[0].table_point[0]));
  EXPECT_TRUE(std::isnan(msg.axes[0].angle_to_normal));

  const geometry::PairingResult back = bus::from_message(msg);
  EXPECT_EQ(back.pairings, 6);
  ASSERT_EQ(back.axes.size(), 2u);
  EXPECT_EQ(back.axes[1].left_index, 3);
  EXPECT_EQ(back.axes[0].right_index, 5);
  EXPECT_EQ(back.axes[0].axis.a, no_table.axis.a);
  EXPECT_EQ(back.axes[0].axis.b, no_table.axis.b);
  EXPECT_FALSE(back.axes[0].hit.has_value());
}

TEST(AxesConvert, TableFrameAxesArriveInTheTableFrame) {
  const geometry::TableFrame table(table_plane());
  const geometry::PairedAxis a = axis_with_hit();
  const geometry::PairedAxis back = bus::from_message(bus::to_message(a, &table));
  EXPECT_LT((back.axis.a - table.to_table(a.axis.a)).norm(), 1e-12);
  EXPECT_LT((back.axis.b - table.to_table(a.axis.b)).norm(), 1e-12);
  ASSERT_TRUE(back.hit.has_value());
  EXPECT_LT((back.hit->point - table.to_table(a.hit->point)).norm(), 1e-12);
  EXPECT_NEAR(back.hit->tilt_deg, 7.5, 1e-12);
  EXPECT_NEAR(table.to_table(a.hit->point).z(), 0.0, 1e-12) << "the hit lies on the table";
}

TEST(AxesConvert, CountThatDisagreesIsAnError) {
  axes_t msg = bus::to_message(geometry::PairingResult{}, 1, nullptr);
  msg.num_axes = 1;
  EXPECT_THROW(bus::from_message(msg), std::invalid_argument);
}
