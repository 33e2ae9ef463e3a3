#include "core/memory_budget.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "core/error.h"

namespace lc {
namespace {

TEST(MemoryBudget, ReservesUpToTheLimitAndNoFurther) {
  MemoryBudget b(1000);
  EXPECT_TRUE(b.tryReserve(600));
  EXPECT_TRUE(b.tryReserve(400));
  EXPECT_EQ(b.used(), 1000u);
  EXPECT_FALSE(b.tryReserve(1));
  EXPECT_EQ(b.used(), 1000u);  // a refused reservation counts nothing
  b.release(500);
  EXPECT_TRUE(b.tryReserve(500));
  // Overflowing requests are refused, not wrapped around.
  EXPECT_FALSE(b.tryReserve(~uint64_t(0)));
}

TEST(MemoryBudget, ErrorNamesWhatAndTheLimit) {
  MemoryBudget b(uint64_t(2) << 30);
  b.reserve(uint64_t(1) << 30, "textures");
  try {
    b.reserve(uint64_t(3) << 30, "textures");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "textures need about 3.0 GB (4.0 GB with what is already loaded), more than "
                           "--max-memory (2.0 GB)");
  }
  EXPECT_EQ(b.used(), uint64_t(1) << 30);
}

TEST(MemoryBudget, ConcurrentReservationsNeverExceedTheLimit) {
  MemoryBudget b(10'000);
  std::vector<std::thread> threads;
  std::atomic<int> granted{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 10'000; ++i)
        if (b.tryReserve(3)) granted++;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(granted.load(), 3333);
  EXPECT_EQ(b.used(), 9999u);
}

TEST(MemoryBudget, DefaultIsAPartOfPhysicalMemory) {
  uint64_t d = MemoryBudget::defaultLimit();
  EXPECT_GT(d, uint64_t(64) << 20);
  EXPECT_LT(d, uint64_t(1) << 50);
}

TEST(ParseBytes, SuffixesAndJunk) {
  EXPECT_EQ(parseBytes("1000"), 1000u);
  EXPECT_EQ(parseBytes("0"), 0u);
  EXPECT_EQ(parseBytes("64k"), 65536u);
  EXPECT_EQ(parseBytes("512M"), uint64_t(512) << 20);
  EXPECT_EQ(parseBytes("8G"), uint64_t(8) << 30);
  EXPECT_EQ(parseBytes("8GB"), uint64_t(8) << 30);
  EXPECT_EQ(parseBytes("1.5G"), uint64_t(3) << 29);
  EXPECT_EQ(parseBytes("2T"), uint64_t(2) << 40);
  for (const char* bad : {"", "-1", "G", "1.2.3", "abc", "1e9", "99999999999999999999", "20000000T", ".", " 1"})
    EXPECT_EQ(parseBytes(bad), std::nullopt) << bad;
}

TEST(FormatBytes, Units) {
  EXPECT_EQ(formatBytes(900), "900 bytes");
  EXPECT_EQ(formatBytes(1536), "1.5 KB");
  EXPECT_EQ(formatBytes(uint64_t(5) << 30), "5.0 GB");
}

}  // namespace
}  // namespace lc
