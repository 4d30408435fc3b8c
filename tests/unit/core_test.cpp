#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "nudge/atomic_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"

using namespace nudge;

namespace {
bool parse(Flags& flags, std::vector<std::string> args) {
  std::vector<char*> argv;
  static std::string program = "prog";
  argv.push_back(program.data());
  for (auto& a : args) argv.push_back(a.data());
  return flags.parse(static_cast<int>(argv.size()), argv.data());
}
}  // namespace

TEST(Flags, ParsesEveryKindAndKeepsPositionals) {
  std::string name = "x";
  int n = 1;
  double d = 0.5;
  bool on = false;
  std::vector<double> pair = {1, 2};
  Flags f("prog", "test");
  f.add_string("name", &name, "");
  f.add_int("n", &n, "");
  f.add_double("d", &d, "");
  f.add_bool("on", &on, "");
  f.add_doubles("pair", &pair, 2, "");
  ASSERT_TRUE(parse(f, {"a.png", "--name", "bob", "--n=7", "--d", "-2.5", "--on", "--pair", "30", "90", "b.png"}));
  EXPECT_EQ(name, "bob");
  EXPECT_EQ(n, 7);
  EXPECT_DOUBLE_EQ(d, -2.5);
  EXPECT_TRUE(on);
  EXPECT_EQ(pair, (std::vector<double>{30, 90}));
  EXPECT_EQ(f.positional(), (std::vector<std::string>{"a.png", "b.png"}));
  EXPECT_TRUE(f.given("n"));
  EXPECT_FALSE(f.given("zzz"));
}

TEST(Flags, BadValuesNameTheFlag) {
  int n = 0;
  double d = 0;
  Flags f("prog", "test");
  f.add_int("n", &n, "");
  f.add_double("d", &d, "");
  auto message = [&](std::vector<std::string> args) {
    try {
      parse(f, args);
    } catch (const FlagError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({"--n", "seven"}).find("--n"), std::string::npos);
  EXPECT_NE(message({"--d", "nan"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--d", "1e999"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--d"}).find("--d"), std::string::npos);
  EXPECT_NE(message({"--nope"}).find("--nope"), std::string::npos);
}

TEST(Json, EscapesAndNestsAndWritesNullForNonFinite) {
  JsonWriter j;
  j.begin_object();
  j.field("s", "a\"b\\c\n").field("n", 3).field("x", std::nan("")).key("arr").begin_array();
  j.value(1).value(true).begin_object().field("k", "v").end_object();
  j.end_array().end_object();
  EXPECT_EQ(j.str(), R"({"s":"a\"b\\c\n","n":3,"x":null,"arr":[1,true,{"k":"v"}]})");
}

TEST(AtomicFile, ReplacesContentsAndLeavesNoTemporaries) {
  const std::string path = testing::TempDir() + "/atomic_test.txt";
  write_file_atomically(path, "first");
  write_file_atomically(path, "second");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second");
  EXPECT_THROW(write_file_atomically("/nonexistent-dir/x.txt", "y"), std::runtime_error);
}
