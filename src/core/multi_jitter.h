// Sample positions in a pixel: correlated multi-jittered sampling (Chiu, Shirley & Wang 1994,
// "Multi-jittered sampling"; Kensler 2013, "Correlated multi-jittered sampling", Pixar).
//
// m x n samples, one in each cell of an m x n grid (stratified in 2-D, as plain jitter is),
// and also one in each of the m*n columns of width 1/(m n) and each of the m*n rows of height
// 1/(m n) (the N-rooks property). Why it matters: the coverage of a pixel by a vertical or
// horizontal edge is measured to within one of those thin columns or rows, 1/(m n) of the
// pixel, where plain jitter leaves each of the ~m cells the edge crosses a random error of up
// to 1/(m n): about sqrt(m) / (m n) in sum (2.7% of the edge's contrast at 7 x 7, which put
// the demo's box edges over 2%; docs/LIGHTCUTS.md). Slanted edges keep the 2-D strata.
//
// Kensler's correlated form: the sample in column i, row j lies in thin column i*n + py[j]
// and thin row j*m + px[i], with one permutation px of the m columns and one py of the n
// rows for the whole pixel, and a uniform jitter within its thin column and row.
#pragma once

#include <vector>

#include "core/math.h"
#include "core/rng.h"

namespace lc {

// Fills `out` with the m x n samples of a pixel, row by row (index j * m + i), in [0, 1)^2.
// With keepMiddle (m == n, odd) the middle cell's sample is the pixel's centre (0.5, 0.5)
// exactly: the permutations fix the middle index and that sample is not jittered, so a
// caller that already has the centre can take the others alone.
inline void multiJittered(int m, int n, Rng& rng, std::vector<Vec2>& out, bool keepMiddle = false) {
  keepMiddle = keepMiddle && m == n && m % 2 == 1;
  const int cm = keepMiddle ? m / 2 : -1, cn = keepMiddle ? n / 2 : -1;
  auto permutation = [&](int k, int fixed) {
    std::vector<int> p(static_cast<size_t>(k));
    for (int i = 0; i < k; ++i) p[size_t(i)] = i;
    // Fisher-Yates over the indices other than `fixed`.
    std::vector<int> free;
    for (int i = 0; i < k; ++i)
      if (i != fixed) free.push_back(i);
    for (size_t i = free.size(); i > 1; --i) std::swap(p[size_t(free[i - 1])], p[size_t(free[rng.below(uint32_t(i))])]);
    return p;
  };
  const std::vector<int> px = permutation(m, cm), py = permutation(n, cn);
  out.resize(size_t(m) * size_t(n));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) {
      const bool middle = i == cm && j == cn;
      const float jx = middle ? 0.5f : rng.uniform(), jy = middle ? 0.5f : rng.uniform();
      // Kept below 1: (i + (k + jx) / n) / m rounds to 1 for the last column's last sliver.
      const float x = (float(i) + (float(py[size_t(j)]) + jx) / float(n)) / float(m);
      const float y = (float(j) + (float(px[size_t(i)]) + jy) / float(m)) / float(n);
      out[size_t(j) * size_t(m) + size_t(i)] = Vec2(std::min(x, 0x1.fffffep-1f), std::min(y, 0x1.fffffep-1f));
    }
}

}  // namespace lc
