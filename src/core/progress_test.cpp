#include "core/progress.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace lc {
namespace {

TEST(Progress, ReportsFractionsInOrderFromManyThreadsAndEndsAtOneOnce) {
  std::vector<double> seen;
  std::atomic<int> inside{0};
  bool overlapped = false;
  ProgressFn fn = [&](double f) {
    // Calls never overlap, so a plain vector is safe here.
    if (inside.fetch_add(1) != 0) overlapped = true;
    seen.push_back(f);
    inside.fetch_sub(1);
  };
  {
    Progress p(fn, 400);
    tbb::parallel_for(0, 400, [&](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      p.add(1);
    });
    p.finish();
    p.finish();  // a second finish reports nothing
  }              // nor does the destructor after finish
  EXPECT_FALSE(overlapped);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1.0), 1);
  for (double f : seen) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
}

TEST(Progress, ThrottlesReportsToAboutTenASecond) {
  int calls = 0;
  ProgressFn fn = [&](double) { ++calls; };
  Progress p(fn, 1e6);
  for (int i = 0; i < 1000000; ++i) p.add(1);  // well under a second of work
  p.finish();
  EXPECT_LE(calls, 12);
  EXPECT_GE(calls, 1);
}

TEST(Progress, DestructorFinishesAPhaseLeftOpen) {
  std::vector<double> seen;
  ProgressFn fn = [&](double f) { seen.push_back(f); };
  { Progress p(fn, 0); }  // a total of 0 counts as 1
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], 1.0);
}

}  // namespace
}  // namespace lc
