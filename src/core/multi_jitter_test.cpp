// Multi-jittered sample positions: one per cell, one per thin column and row (so a
// vertical or horizontal edge's coverage is exact to one thin column), the middle kept at
// the centre, and the same positions for the same stream.
#include "core/multi_jitter.h"

#include <gtest/gtest.h>

#include <set>

namespace lc {
namespace {

void expectMultiJittered(const std::vector<Vec2>& p, int m, int n) {
  ASSERT_EQ(int(p.size()), m * n);
  std::set<int> cells, columns, rows;
  for (const Vec2& u : p) {
    ASSERT_TRUE(u.x >= 0 && u.x < 1 && u.y >= 0 && u.y < 1) << u.x << "," << u.y;
    cells.insert(int(u.y * float(n)) * m + int(u.x * float(m)));
    columns.insert(int(u.x * float(m * n)));
    rows.insert(int(u.y * float(m * n)));
  }
  EXPECT_EQ(int(cells.size()), m * n);
  EXPECT_EQ(int(columns.size()), m * n);
  EXPECT_EQ(int(rows.size()), m * n);
}

TEST(MultiJittered, OnePerCellAndPerThinColumnAndRow) {
  std::vector<Vec2> p;
  for (auto [m, n] : {std::pair{8, 8}, {7, 7}, {6, 4}, {7, 1}, {2, 1}, {3, 3}}) {
    for (uint64_t stream = 0; stream < 20; ++stream) {
      Rng rng(3, stream);
      multiJittered(m, n, rng, p);
      expectMultiJittered(p, m, n);
    }
  }
}

TEST(MultiJittered, TheMiddleIsThePixelCentre) {
  std::vector<Vec2> p;
  for (int g : {3, 5, 7, 9}) {
    Rng rng(1, uint64_t(g));
    multiJittered(g, g, rng, p, /*keepMiddle=*/true);
    expectMultiJittered(p, g, g);
    EXPECT_EQ(p[size_t(g * g / 2)].x, 0.5f);
    EXPECT_EQ(p[size_t(g * g / 2)].y, 0.5f);
  }
}

// The share of samples left of a vertical line (or below a horizontal one) is the share of
// the pixel's area within one thin column, 1/(m n); plain jitter on 7 x 7 cells misses it by
// up to 7/49 and by more than 1/49 on most of these lines.
TEST(MultiJittered, EdgeCoverageWithinOneThinColumn) {
  std::vector<Vec2> p;
  Rng lines(5, 0);
  int jitterMisses = 0;
  for (int k = 0; k < 200; ++k) {
    const float e = lines.uniform();
    Rng rng(9, uint64_t(k));
    multiJittered(7, 7, rng, p);
    int left = 0, below = 0;
    for (const Vec2& u : p) left += u.x < e, below += u.y < e;
    EXPECT_LE(std::fabs(float(left) / 49 - e), 1.0f / 49 + 1e-6f) << e;
    EXPECT_LE(std::fabs(float(below) / 49 - e), 1.0f / 49 + 1e-6f) << e;
    // The same count with plain jitter in the same cells.
    int jitterLeft = 0;
    for (int c = 0; c < 49; ++c) jitterLeft += (float(c % 7) + rng.uniform()) / 7 < e;
    jitterMisses += std::fabs(float(jitterLeft) / 49 - e) > 1.0f / 49 + 1e-6f;
  }
  EXPECT_GT(jitterMisses, 50);  // what the thin columns buy
}

TEST(MultiJittered, SameStreamSamePositions) {
  std::vector<Vec2> a, b, c;
  Rng r1(1, 42), r2(1, 42), r3(1, 43);
  multiJittered(7, 7, r1, a);
  multiJittered(7, 7, r2, b);
  multiJittered(7, 7, r3, c);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
  }
  bool differ = false;
  for (size_t i = 0; i < a.size(); ++i) differ |= a[i].x != c[i].x;
  EXPECT_TRUE(differ);
}

}  // namespace
}  // namespace lc
