// nudge::Flags on CLI11: what users know of every service's flags stays as it was.
#include <gtest/gtest.h>

#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"

using nudge::FlagError;
using nudge::Flags;

namespace {
bool parse_args(Flags& flags, std::vector<std::string> args) {
  std::vector<char*> argv;
  static std::string program = "prog";
  argv.push_back(program.data());
  for (auto& a : args) argv.push_back(a.data());
  return flags.parse(static_cast<int>(argv.size()), argv.data());
}

std::string error_of(Flags& flags, std::vector<std::string> args) {
  try {
    parse_args(flags, std::move(args));
  } catch (const FlagError& e) {
    return e.what();
  }
  return "";
}

struct Fixture {
  std::string name = "x";
  int n = 1;
  bool on = false;
  std::vector<double> canny = {30, 90};
  Flags flags{"prog", "a test program"};
  Fixture() {
    flags.add_string("name", &name, "a name");
    flags.add_int("n", &n, "a count");
    flags.add_bool("on", &on, "a switch");
    flags.add_doubles("canny", &canny, 2, "two thresholds");
    flags.set_positional("FILES", "input files");
  }
};
}  // namespace

TEST(FlagsBehaviour, TheLastOfARepeatedFlagWins) {
  Fixture f;
  ASSERT_TRUE(parse_args(f.flags, {"--n", "2", "--canny", "1", "2", "--n=5", "--canny", "3", "4"}));
  EXPECT_EQ(f.n, 5);
  EXPECT_EQ(f.canny, (std::vector<double>{3, 4}));
}

TEST(FlagsBehaviour, ErrorsNameTheFlagInOurWords) {
  Fixture f;
  EXPECT_EQ(error_of(f.flags, {"--nope", "1"}), "unknown flag --nope (see --help)");
  EXPECT_EQ(error_of(f.flags, {"--nope=1"}), "unknown flag --nope (see --help)");
  EXPECT_EQ(error_of(f.flags, {"--on=1"}), "--on takes no value");
  EXPECT_EQ(error_of(f.flags, {"--canny", "1"}), "--canny needs 2 value(s)");
  EXPECT_EQ(error_of(f.flags, {"--n"}), "--n needs 1 value(s)");
  EXPECT_EQ(error_of(f.flags, {"--n", "x"}), "--n: expected an integer, got 'x'");
  EXPECT_EQ(error_of(f.flags, {"--canny", "1", "nan"}), "--canny: expected a finite number, got 'nan'");
}

TEST(FlagsBehaviour, NegativeNumbersAreValuesAndPositionalsKeepTheirPlace) {
  Fixture f;
  ASSERT_TRUE(parse_args(f.flags, {"a", "--canny", "-1.5", "-2", "b", "--name", "bob", "c"}));
  EXPECT_EQ(f.canny, (std::vector<double>{-1.5, -2}));
  EXPECT_EQ(f.name, "bob");
  EXPECT_EQ(f.flags.positional(), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_TRUE(f.flags.given("canny"));
  EXPECT_FALSE(f.flags.given("on"));
}

TEST(FlagsBehaviour, HelpAnywherePrintsOurTextAndStops) {
  Fixture f;
  std::ostringstream captured;
  std::streambuf* old = std::cout.rdbuf(captured.rdbuf());
  const bool go_on = parse_args(f.flags, {"--n", "3", "-h"});
  std::cout.rdbuf(old);
  EXPECT_FALSE(go_on);
  EXPECT_EQ(captured.str(), f.flags.help());
  EXPECT_EQ(f.flags.help(),
            "usage: prog [options] FILES\na test program\n\n  FILES  input files\n\noptions:\n"
            "  --name V                a name [x]\n"
            "  --n V                   a count [1]\n"
            "  --on                    a switch [off]\n"
            "  --canny V1 V2           two thresholds [30 90]\n"
            "  --help                  this text\n");
}
