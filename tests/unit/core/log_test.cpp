// nudge::log's line format, as scripts and people read it: "<UTC time>.<ms>Z <level> <component>: <message>".
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include "nudge/log.hpp"

namespace {
// What the logging writes to stderr while `body` runs.
template <typename Body>
std::string stderr_of(Body body) {
  const std::string path = testing::TempDir() + "/log_test_" + std::to_string(getpid()) + ".txt";
  std::fflush(stderr);
  const int saved = dup(STDERR_FILENO);
  FILE* file = std::fopen(path.c_str(), "w");
  dup2(fileno(file), STDERR_FILENO);
  body();
  std::fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  std::fclose(file);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(path.c_str());
  return text.str();
}
}  // namespace

TEST(Log, LinesHaveTheUtcTimeTheLevelLetterAndTheComponent) {
  nudge::log::set_component("tester");
  const std::string text = stderr_of([] {
    nudge::log::info() << "published " << 3 << " lines";
    nudge::log::warn() << "slow";
    nudge::log::error() << "bad input 'x'";
  });
  const std::regex line(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z ([DIWE]) tester: (.*))");
  std::istringstream lines(text);
  std::vector<std::string> levels, messages;
  for (std::string l; std::getline(lines, l);) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(l, m, line)) << "'" << l << "'";
    levels.push_back(m[1]);
    messages.push_back(m[2]);
  }
  EXPECT_EQ(levels, (std::vector<std::string>{"I", "W", "E"}));
  EXPECT_EQ(messages, (std::vector<std::string>{"published 3 lines", "slow", "bad input 'x'"}));
}

TEST(Log, DebugLinesOnlyAtTheDebugLevel) {
  nudge::log::set_component("tester");
  const std::string quiet = stderr_of([] { nudge::log::debug() << "hidden"; });
  EXPECT_EQ(quiet, "");
  nudge::log::set_level(nudge::log::Level::Debug);
  const std::string verbose = stderr_of([] { nudge::log::debug() << "shown {braces} kept"; });
  nudge::log::set_level(nudge::log::Level::Info);
  EXPECT_NE(verbose.find(" D tester: shown {braces} kept\n"), std::string::npos) << verbose;
}
