#include <gtest/gtest.h>

#include <sstream>

#include "nudge/progress.hpp"

using nudge::Progress;

namespace {
// A clock the test moves by hand, so that the estimates are exact.
struct FakeClock {
  double now = 100;
  Progress::Clock fn() {
    return [this] { return now; };
  }
};
}  // namespace

TEST(Progress, TerminalShowsEachStepWithTimeLeftAndEndsWithASummary) {
  std::ostringstream out;
  FakeClock clock;
  {
    Progress p("exp", 4, out, /*interactive=*/true, clock.fn());
    p.step("scene s01");
    clock.now += 10;
    p.step("scene s02");  // one done in 10 s: 3 left → 30 s
    EXPECT_DOUBLE_EQ(p.remaining_s(), 30);
    clock.now += 30;
    p.step("scene s03");  // two done in 40 s → 2 left at 20 s each
    EXPECT_DOUBLE_EQ(p.remaining_s(), 40);
    clock.now += 20;
    p.step("scene s04");
    clock.now += 12;
    p.finish("3 segmented");
    EXPECT_EQ(p.done(), 4);
  }
  const std::string text = out.str();
  EXPECT_EQ(text.rfind("exp: 4 steps\n", 0), 0u) << text;
  EXPECT_NE(text.find("\r[1/4] scene s01"), std::string::npos) << text;
  EXPECT_NE(text.find("\r[2/4] scene s02 … 30 s left"), std::string::npos) << text;
  EXPECT_NE(text.find("\r[3/4] scene s03 … 40 s left"), std::string::npos) << text;
  EXPECT_NE(text.find("exp: done 4/4 in 1 m 12 s — 3 segmented\n"), std::string::npos) << text;
  // The destructor of a finished job adds nothing.
  EXPECT_EQ(text.find("stopped early"), std::string::npos);
}

TEST(Progress, NotATerminalWritesOnlyTheStartAndEndLines) {
  std::ostringstream out;
  FakeClock clock;
  Progress p("calibrate", 3, out, /*interactive=*/false, clock.fn());
  for (const char* view : {"a", "b", "c"}) {
    p.step(view);
    clock.now += 1;
  }
  p.finish();
  EXPECT_EQ(out.str(), "calibrate: 3 steps\ncalibrate: done 3/3 in 3 s\n");
}

TEST(Progress, AShorterStatusBlanksTheRestOfTheLongerOne) {
  std::ostringstream out;
  FakeClock clock;
  Progress p("job", 0, out, true, clock.fn());  // total unknown: no time left shown
  p.step("a long item name");
  p.step("b");
  const std::string text = out.str();
  const std::string longer = "[1] a long item name";
  EXPECT_NE(text.find("\r" + longer), std::string::npos) << text;
  EXPECT_NE(text.find("\r[2] b" + std::string(longer.size() - 6, ' ')), std::string::npos) << text;
  EXPECT_LT(p.remaining_s(), 0);
}

TEST(Progress, AnUnfinishedJobSaysSoWhenDestroyed) {
  std::ostringstream out;
  FakeClock clock;
  {
    Progress p("exp", 5, out, false, clock.fn());
    p.step("one");
    clock.now += 2;
    p.step("two");
  }
  EXPECT_NE(out.str().find("exp: done 2/5 in 2 s — stopped early\n"), std::string::npos) << out.str();
}

TEST(Progress, FormatsDurationsForPeople) {
  EXPECT_EQ(Progress::format_duration(0.85), "850 ms");
  EXPECT_EQ(Progress::format_duration(34.4), "34 s");
  EXPECT_EQ(Progress::format_duration(72), "1 m 12 s");
  EXPECT_EQ(Progress::format_duration(2 * 3600 + 5 * 60), "2 h 05 m");
  EXPECT_EQ(Progress::format_duration(-1), "?");
}

TEST(Progress, NotesGoAboveTheStatusLine) {
  std::ostringstream out;
  FakeClock clock;
  Progress p("exp", 2, out, true, clock.fn());
  p.step("s01");
  p.note("s01: 3 objects");
  const std::string text = out.str();
  // The status is blanked, the note written on its own line, then the status redrawn.
  EXPECT_NE(text.find("\r[1/2] s01\r         \rs01: 3 objects\n\r[1/2] s01"), std::string::npos) << text;
  std::ostringstream plain;
  Progress q("exp", 2, plain, false, clock.fn());
  q.step("s01");
  q.note("s01: 3 objects");
  EXPECT_EQ(plain.str(), "exp: 2 steps\ns01: 3 objects\n");
  q.finish();
}
