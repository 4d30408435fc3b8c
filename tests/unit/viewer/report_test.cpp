// nudge_viewer's run report from a run folder laid out as the supervisor writes it; and the
// report in headless Chromium from the file itself (no server): a screenshot.
#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <regex>

#include "nudge/viewer/report.hpp"

namespace fs = std::filesystem;
using nudge::viewer::render_run_report;
using nudge::viewer::StateEntry;

namespace {

int count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

// A run of two attempts: the first segmented (stills, mask, cut-out, fig. 6.6, two stages, a
// learned view, a tracking trace), the second tipped over (a still only).
std::string make_run(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "attempt_01" / "stages");
  fs::create_directories(dir / "attempt_01" / "views");
  fs::create_directories(dir / "attempt_02");
  const cv::Mat grey(60, 80, CV_8UC1, cv::Scalar(128));
  for (const char* f : {"attempt_01/before.png", "attempt_01/after.png", "attempt_01/mask.png", "attempt_01/cutout.png",
                        "attempt_01/workspace.png", "attempt_01/stages/c_difference.png", "attempt_01/stages/e_refined.png",
                        "attempt_01/views/view_00.png", "attempt_02/before.png"})
    cv::imwrite((dir / f).string(), grey);
  std::ofstream(dir / "summary.json") << R"({"run_id": "r1", "surveys": 3, "attempts": 2, "segmented": 1,
    "end_reason": "no candidate <left>", "outcomes": {"segmented": 1, "tipped or lost": 1},
    "attempt_list": [
      {"attempt": 1, "outcome": "segmented", "reason": "segmented", "target": [0.301, -0.02, 0], "rest": [0.304, -0.044, 0],
       "mask_pixels": 2500, "motion_frames": 15, "started_s": 2.4, "ended_s": 26.7,
       "track_trace": {"left": [[0.0, 2, -100, -0.12, 1, 0], [0.1, 2, -101, -0.13, 1, 0], [0.2, 2, -103, -0.15, 1, 0]],
                       "right": []}},
      {"attempt": 2, "outcome": "tipped or lost", "reason": "0 upright axes", "target": [0.187, 0.109, 0], "rest": null,
       "mask_pixels": 0, "started_s": 29.7, "ended_s": 53.9, "track_trace": {"left": [], "right": []}}]})";
  return dir.string();
}

std::vector<StateEntry> states() {
  std::vector<StateEntry> out(3);
  out[0].state = "FIND_CANDIDATES", out[0].utime = 1000000;
  out[1].state = "NUDGE", out[1].utime = 3500000, out[1].attempt = 1, out[1].reason = "nudging candidate 2";
  out[2].state = "DONE", out[2].utime = 60000000, out[2].attempt = 2;
  return out;
}

}  // namespace

TEST(RunReport, ShowsFiguresTimelineAndEachAttemptsPicturesByRelativePath) {
  const std::string dir = make_run("report");
  const std::string html = render_run_report(dir, states());
  EXPECT_NE(html.find("<h1>nudge run r1</h1>"), std::string::npos);
  EXPECT_NE(html.find("no candidate &lt;left&gt;"), std::string::npos) << "text is escaped";
  EXPECT_EQ(count(html, "<tr><td>[0-9.]+</td><td>(FIND_CANDIDATES|NUDGE|DONE)</td>"), 3);
  EXPECT_NE(html.find("<td>2.5</td><td>NUDGE</td>"), std::string::npos) << "times from the first state";
  EXPECT_NE(html.find("<tr><td>FIND_CANDIDATES</td><td>2.5</td><td>1</td></tr>"), std::string::npos)
      << "time per state: until the next transition";
  EXPECT_NE(html.find("<tr><td>NUDGE</td><td>56.5</td><td>1</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<h3>learned views (1)</h3>"), std::string::npos);
  EXPECT_EQ(count(html, "<section class=\"attempt\" id=\"attempt_0[12]\">"), 2) << "linkable: report.html#attempt_01";
  EXPECT_NE(html.find("<td>segmented 1, tipped or lost 1</td>"), std::string::npos) << "the outcomes, readable";
  EXPECT_EQ(html.find("objects learned"), std::string::npos) << "a run without learning has no such figure";
  EXPECT_NE(html.find("target (301, -20) mm, at rest (304, -44) mm"), std::string::npos);
  EXPECT_NE(html.find("<img src=\"attempt_01/stages/c_difference.png\""), std::string::npos);
  EXPECT_NE(html.find("<img src=\"attempt_01/views/view_00.png\""), std::string::npos) << "learned views shown";
  EXPECT_EQ(count(html, "<img src=\"attempt_01/"), 8);
  EXPECT_EQ(count(html, "<img src=\"attempt_02/"), 1) << "only the pictures that exist";
  EXPECT_EQ(count(html, "<polyline"), 1) << "one tracker traced";
  EXPECT_EQ(html.find(dir), std::string::npos) << "no absolute paths: the folder can move";
}

TEST(RunReport, ARunOfOneStateIsOneTimelineRowAndItsTimeAddsUp) {
  const std::string dir = make_run("report_rotate");
  std::vector<StateEntry> s(5);
  s[0].state = "GRASP", s[0].utime = 0, s[0].attempt = 1;
  s[1].state = "ROTATE", s[1].utime = 1000000, s[1].attempt = 1, s[1].reason = "view 1 of 12";
  s[2].state = "ROTATE", s[2].utime = 2000000, s[2].attempt = 1, s[2].reason = "turning the wrist 30 deg";
  s[3].state = "ROTATE", s[3].utime = 3500000, s[3].attempt = 1, s[3].reason = "view 2 of 12";
  s[4].state = "LEARN", s[4].utime = 4000000, s[4].attempt = 1;
  const std::string html = render_run_report(dir, s);
  EXPECT_EQ(count(html, "<td>ROTATE</td><td>1</td>"), 1) << html;
  EXPECT_NE(html.find("view 1 of 12 … view 2 of 12 (3 transitions)"), std::string::npos);
  EXPECT_NE(html.find("<tr><td>ROTATE</td><td>3.0</td><td>3</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><td>LEARN</td><td>0.0</td><td>1</td></tr>"), std::string::npos) << "the last: no time yet";
}

TEST(RunReport, ARunThatLearnedSaysHowManyObjectsAndWhatRecognitionAnswered) {
  const std::string dir = make_run("report_learned");
  std::ofstream(dir + "/summary.json") << R"({"run_id": "r2", "attempts": 2, "segmented": 1, "learned": 1,
    "outcomes": {"segmented": 1, "known": 1}, "attempt_list": [
      {"attempt": 1, "outcome": "segmented", "learning": {"outcome": "learned", "reason": "learned as 'mug'",
       "recognised": "", "recognition_reason": "empty database", "grasp_plan_ms": 61.7}},
      {"attempt": 2, "outcome": "known", "learning": {"outcome": "known", "recognised": "mug"}}]})";
  const std::string html = render_run_report(dir, states());
  EXPECT_NE(html.find("<tr><th>objects learned</th><td>1</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("recognition: nothing known (empty database) · learning: learned (learned as 'mug') · "
                      "grasp planned in 62 ms"), std::string::npos) << html;
  EXPECT_NE(html.find("recognition: recognised as mug · learning: known</p>"), std::string::npos);
  EXPECT_EQ(html.find("<h3>recognition</h3>"), std::string::npos) << "no match picture yet";

  // The learner's match picture, kept by the supervisor in the attempt's folder, has its own row.
  cv::imwrite(dir + "/attempt_02/recognition_match.png", cv::Mat(60, 80, CV_8UC3, cv::Scalar(0, 0, 200)));
  const std::string with_match = render_run_report(dir, states());
  const size_t heading = with_match.find("<h3>recognition</h3>");
  ASSERT_NE(heading, std::string::npos);
  EXPECT_GT(heading, with_match.find("id=\"attempt_02\"")) << "under the attempt that recognised it";
  EXPECT_EQ(count(with_match, "<img src=\"attempt_02/recognition_match.png\""), 1) << "shown once, not again below";
}

TEST(RunReport, ShowsTheIoUInSimulationPerObjectAndPerAttempt) {
  const std::string dir = make_run("report_iou");
  std::vector<nudge::viewer::SimulationScore> scores(3);
  scores[0] = {1, 2, "mug", 0.8734};
  scores[1] = {2, 2, "mug", 0.61};   // the same object segmented again, less well
  scores[2] = {3, 0, "cup", 0.42};   // an attempt the summary does not list still counts for its object
  const std::string html = render_run_report(dir, states(), scores);
  ASSERT_NE(html.find("<table id=\"iou\">"), std::string::npos);
  EXPECT_NE(html.find("<tr><td>mug (object 2)</td><td>1 (0.873), 2 (0.610)</td><td class=\"best\">0.873</td></tr>"),
            std::string::npos) << html;
  EXPECT_NE(html.find("<tr><td>cup (object 0)</td><td>3 (0.420)</td><td class=\"best\">0.420</td></tr>"),
            std::string::npos);
  EXPECT_LT(html.find("cup (object 0)"), html.find("mug (object 2)")) << "objects in the scene's order";
  EXPECT_NE(html.find("IoU (simulation) 0.873 with mug (object 2)"), std::string::npos) << "in attempt 1's section";
  EXPECT_NE(html.find("IoU (simulation) 0.610 with mug (object 2)"), std::string::npos) << "in attempt 2's section";
  // Without scores (a run on the robot) there is no IoU at all.
  EXPECT_EQ(render_run_report(dir, states()).find("IoU"), std::string::npos);
}

TEST(RunReport, AMissingSummaryIsNamed) {
  try {
    render_run_report("/nonexistent/run", {});
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/run/summary.json"), std::string::npos);
  }
}

TEST(RunReport, OpensInHeadlessChromiumWithNoServer) {
  const std::string chromium = "/usr/bin/chromium";
  if (access(chromium.c_str(), X_OK) != 0) GTEST_SKIP() << "chromium is not installed (Debian package chromium)";
  const std::string dir = make_run("report_chromium");
  std::ofstream(dir + "/report.html") << render_run_report(dir, states());
  const std::string shot = dir + "/report.png";
  const std::string dom = dir + "/dom.html";
  const std::string base = "timeout 60 " + chromium + " --headless --no-sandbox --disable-gpu --user-data-dir=" + dir +
                           "/profile --window-size=1200,1000 ";
  ASSERT_EQ(std::system((base + "--dump-dom file://" + dir + "/report.html > " + dom + " 2>/dev/null").c_str()), 0);
  ASSERT_EQ(std::system((base + "--screenshot=" + shot + " file://" + dir + "/report.html > /dev/null 2>&1").c_str()), 0);
  std::ifstream in(dom);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(count(text, "<section class=\"attempt\" id=\"attempt_0[12]\">"), 2);
  EXPECT_TRUE(fs::exists(shot) && fs::file_size(shot) > 5000);
  std::cout << "screenshot of the report: " << shot << "\n";
}
