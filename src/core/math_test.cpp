#include "core/math.h"

#include <gtest/gtest.h>

#include "core/rng.h"

namespace lc {

TEST(Mat4, InverseAffineRoundTrips) {
  Mat4 m = Mat4::translate(1, -2, 3) * Mat4::rotate(1, 2, 3, 0.7) * Mat4::scale(2, 0.5, 3);
  m.m[0][1] += 0.3;  // shear
  Mat4 inv;
  ASSERT_TRUE(m.inverseAffine(inv));
  Mat4 id = m * inv;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(id.m[i][j], i == j ? 1.0 : 0.0, 1e-12);
}

TEST(Mat4, SingularMatrixHasNoInverse) {
  Mat4 inv;
  EXPECT_FALSE(Mat4::scale(1, 0, 1).inverseAffine(inv));
}

TEST(Mat4, RotateQuarterTurnAboutZ) {
  Vec3 p = Mat4::rotate(0, 0, 2, kPi / 2).point(Vec3(1, 0, 0));
  EXPECT_NEAR(p.x, 0, 1e-6);
  EXPECT_NEAR(p.y, 1, 1e-6);
}

TEST(Mat4, NormalsUseInverseTranspose) {
  // A plane z = x (normal (-1,0,1)) scaled by 2 in x stays perpendicular to its tangents.
  Mat4 m = Mat4::scale(2, 1, 1), inv;
  ASSERT_TRUE(m.inverseAffine(inv));
  Vec3 n = inv.normalFromInverse(Vec3(-1, 0, 1));
  Vec3 t = m.vector(Vec3(1, 0, 1));
  EXPECT_NEAR(dot(n, t), 0, 1e-6);
}

TEST(Bounds3, DistanceToBox) {
  Bounds3 b(Vec3(0, 0, 0), Vec3(1, 1, 1));
  EXPECT_FLOAT_EQ(b.distance2(Vec3(0.5f, 0.5f, 0.5f)), 0);
  EXPECT_FLOAT_EQ(b.distance2(Vec3(3, 0.5f, 0.5f)), 4);
  EXPECT_FLOAT_EQ(b.distance2(Vec3(2, 2, 0.5f)), 2);
}

TEST(Basis, IsOrthonormal) {
  Rng rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    Vec3 n = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    Vec3 u, v;
    orthonormalBasis(n, u, v);
    EXPECT_NEAR(dot(u, v), 0, 1e-5);
    EXPECT_NEAR(dot(u, n), 0, 1e-5);
    EXPECT_NEAR(length(u), 1, 1e-5);
    EXPECT_NEAR(length(v), 1, 1e-5);
  }
}

TEST(Rng, StreamsAreDeterministicAndDistinct) {
  Rng a(7, 1), b(7, 1), c(7, 2);
  for (int i = 0; i < 100; ++i) {
    uint32_t x = a.next();
    EXPECT_EQ(x, b.next());
  }
  int same = 0;
  for (int i = 0; i < 100; ++i) same += a.next() == c.next();
  EXPECT_LT(same, 3);
}

TEST(Rng, UniformIsInUnitInterval) {
  Rng r(3, 4);
  double sum = 0;
  for (int i = 0; i < 100000; ++i) {
    float u = r.uniform();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
  }
  EXPECT_NEAR(sum / 100000, 0.5, 0.01);
}

TEST(PowNonNegative, MatchesStdPowAndIsMonotone) {
  for (float e : {0.0f, 1.0f, 2.0f, 7.0f, 20.0f, 60.0f, 128.0f, 2.5f, 0.3f}) {
    float prev = -1;
    for (int i = 0; i <= 1000; ++i) {
      float x = float(i) / 1000;
      float p = powNonNegative(x, e), q = std::pow(x, e);
      EXPECT_NEAR(p, q, 2e-5f * std::max(q, 1e-30f) + 1e-37f) << "x=" << x << " e=" << e;
      EXPECT_GE(p, prev) << "not monotone at x=" << x << " e=" << e;
      prev = p;
    }
  }
  EXPECT_EQ(powNonNegative(0.0f, 0.0f), 1.0f);  // as std::pow: a shininess of 0 is a constant 1
}

}  // namespace lc

namespace lc {
namespace {

// Ten million terms of 0.1 (not a float): the double sum is exact to 1e-9, a float one
// would be off by percents.
TEST(Vec3d, SumsMillionsOfFloatsExactly) {
  Vec3d s;
  const Vec3 t(0.1f, 0.2f, 0.3f);
  for (int i = 0; i < 10'000'000; ++i) s += t;
  const Vec3 v = s.toFloat();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(v[k], 1e7 * double(t[k]), 1e-6 * 1e7 * double(t[k]));
  EXPECT_NEAR(luminance(s), 1e7 * double(luminance(t)), 1e-6 * 1e7 * double(luminance(t)));
}

}  // namespace
}  // namespace lc
