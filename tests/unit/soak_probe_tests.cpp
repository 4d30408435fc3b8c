// The soak recorder's readers of /proc and its percentiles (experiments/soak_probe.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <vector>

#include "soak_probe.hpp"

namespace soak = nudge::experiments::soak;

TEST(SoakProbe, ReadsVmRssInMegabytes) {
  const std::string status = "Name:\tnudge-symmetry\nVmPeak:\t  900000 kB\nVmRSS:\t   53248 kB\nThreads:\t3\n";
  const auto rss = soak::parse_vm_rss_mb(status);
  ASSERT_TRUE(rss);
  EXPECT_DOUBLE_EQ(*rss, 52.0);
  EXPECT_FALSE(soak::parse_vm_rss_mb("Name:\tzombie\nState:\tZ (zombie)\n"));  // a zombie has none
}

TEST(SoakProbe, CountsCpuTicksAfterTheLastParenthesisOfTheCommand) {
  // A command with a space and a ')' of its own must not shift the fields.
  const std::string stat = "4242 (nudge (x) y) S 1 4242 4242 0 -1 4194560 100 0 0 0 1234 567 0 0 20 0 3 0";
  const auto ticks = soak::parse_cpu_ticks(stat);
  ASSERT_TRUE(ticks);
  EXPECT_EQ(*ticks, 1234 + 567);
  EXPECT_FALSE(soak::parse_cpu_ticks("4242 (cut short) S 1 2"));
  EXPECT_FALSE(soak::parse_cpu_ticks("no parenthesis at all"));
}

TEST(SoakProbe, ReadsTheDropsOfEverySocketFromProcNetUdp) {
  const std::string udp =
      "   sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref pointer drops\n"
      "  101: 4340FFEF:1DEF 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 31337 2 0000000000000000 17\n"
      "  102: 00000000:D431 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 31338 2 0000000000000000 0\n";
  const auto drops = soak::parse_udp_drops(udp);
  ASSERT_EQ(drops.size(), 2u);
  EXPECT_EQ(drops.at(31337), 17);
  EXPECT_EQ(drops.at(31338), 0);
}

TEST(SoakProbe, SamplesThisProcess) {
  const auto sample = soak::sample_process(getpid());
  ASSERT_TRUE(sample);
  EXPECT_GT(sample->rss_mb, 1.0);
  EXPECT_GE(sample->cpu_seconds, 0.0);
  EXPECT_FALSE(soak::sample_process(-5));
}

TEST(SoakProbe, QuantilesInterpolateBetweenSortedSamples) {
  const std::vector<double> samples = {40, 10, 30, 20};
  EXPECT_DOUBLE_EQ(soak::quantile(samples, 0.0), 10);
  EXPECT_DOUBLE_EQ(soak::quantile(samples, 0.5), 25);
  EXPECT_DOUBLE_EQ(soak::quantile(samples, 1.0), 40);
  EXPECT_NEAR(soak::quantile(samples, 0.99), 39.7, 1e-9);
  EXPECT_TRUE(std::isnan(soak::quantile({}, 0.5)));
}
