#include <gtest/gtest.h>

#include "nudge/bus/symmetry_convert.hpp"

using namespace nudge;

TEST(SymmetryConvert, LinesSurviveTheMessage) {
  symmetry::Result r;
  r.width = 640;
  r.height = 480;
  r.num_edges = 1234;
  symmetry::Line l;
  l.r = 12.5;
  l.theta = 0.25;
  l.votes = 99;
  l.end1 = {1, 2};
  l.end2 = {3, 4};
  l.seg1 = {5, 6};
  l.seg2 = {7, 8};
  r.lines = {l, l};
  const symmetry_lines_t msg = bus::to_message(r, 42, 7, "left");
  EXPECT_EQ(msg.num_lines, 2);
  EXPECT_EQ(msg.num_edges, 1234);
  const symmetry::Line back = bus::from_message(msg.lines[1]);
  EXPECT_FLOAT_EQ(back.r, 12.5);
  EXPECT_FLOAT_EQ(back.theta, 0.25);
  EXPECT_FLOAT_EQ(back.seg2.y, 8);
}
