// Every kept fuzz input (tests/fuzz/corpus/TARGET: the seeds; tests/fuzz/crashes/TARGET: what
// the fuzzers once broke on) through the same targets as the libFuzzer programs, with the
// normal compiler and without libFuzzer: a fixed crash stays fixed in every build.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "fuzz_targets.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs every file under tests/fuzz/KIND/TARGET; returns how many.
int replay(const nudge::fuzz::Target& target, const std::string& kind) {
  const fs::path dir = fs::path(NUDGE_SOURCE_DIR) / "tests" / "fuzz" / kind / target.name;
  if (!fs::is_directory(dir)) return 0;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().filename().string()[0] == '.') continue;
    const std::vector<uint8_t> bytes = read_bytes(entry.path());
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(target.run(bytes.data(), bytes.size()));
    ++count;
  }
  return count;
}

}  // namespace

TEST(FuzzReplay, EverySeedAndKeptCrashRunsCleanly) {
  for (const auto& target : nudge::fuzz::targets()) {
    SCOPED_TRACE(target.name);
    EXPECT_GT(replay(target, "corpus"), 0) << "every target has a seed corpus";
    replay(target, "crashes");
  }
}

TEST(FuzzReplay, EmptyAndTinyInputsRunCleanly) {
  const uint8_t bytes[4] = {0xFF, 0xD8, 0x89, 0x00};
  for (const auto& target : nudge::fuzz::targets())
    for (size_t size = 0; size <= sizeof bytes; ++size) EXPECT_NO_THROW(target.run(bytes, size)) << target.name;
}
