// Property tests: every cluster bound must be >= the true sum of the cluster's unshadowed
// contributions, over thousands of random configurations of each light kind.
#include "lightcuts/bounds.h"

#include <gtest/gtest.h>

#include "core/rng.h"
#include "lightcuts/cluster.h"

namespace lc::lightcuts {
namespace {

Vec3 randomUnit(Rng& r) {
  for (;;) {
    Vec3 v(2 * r.uniform() - 1, 2 * r.uniform() - 1, 2 * r.uniform() - 1);
    float l2 = length2(v);
    if (l2 > 1e-4f && l2 <= 1) return v / std::sqrt(l2);
  }
}

// A direction within `angle` radians of `axis`.
Vec3 randomInCone(Rng& r, const Vec3& axis, float angle) {
  float cosT = 1 - r.uniform() * (1 - std::cos(angle));
  float sinT = std::sqrt(std::max(0.0f, 1 - cosT * cosT));
  float phi = 2 * kPi * r.uniform();
  Vec3 u, v;
  orthonormalBasis(axis, u, v);
  return normalize(axis * cosT + u * (sinT * std::cos(phi)) + v * (sinT * std::sin(phi)));
}

LightGroup randomGroup(Rng& r, LightType type) {
  LightGroup g;
  switch (r.below(4)) {
    case 0: g.atten = Attenuation{0, 0, 1, kInf}; break;
    case 1: g.atten = Attenuation{r.uniform(), r.uniform(), r.uniform() * 0.5f, kInf}; break;
    case 2: g.atten = Attenuation{0.25f, 0.003372407f, 0.000045492f, kInf}; break;
    default: g.atten = Attenuation{1, 0, 0, 2 + 5 * r.uniform()}; break;
  }
  if (type == LightType::Directional) g.atten = Attenuation{0, 0, 0, kInf};
  if (type == LightType::Spot) {
    g.falloff.exponent = r.below(2) ? 0.0f : 10 * r.uniform();
    g.falloff.cosCutoff = std::cos(kPi * (0.1f + 0.8f * r.uniform()));
    if (r.below(2)) {
      float outer = kPi * 0.4f * r.uniform();
      float inner = outer * r.uniform();
      g.falloff.cosOuter = std::cos(outer);
      g.falloff.cosInner = std::max(std::cos(inner), g.falloff.cosOuter + 1e-6f);
    }
  }
  g.diffuseOnly = r.below(4) == 0;
  return g;
}

struct Config {
  LightSet set;
  LightNode node;
  ShadingPoint sp;
};

// A random cluster of one type plus a random shading point, sometimes inside the
// cluster's box, sometimes facing away.
Config randomConfig(Rng& r, LightType type) {
  Config c;
  c.set.groups.push_back(randomGroup(r, type));
  int n = 1 + int(r.below(12));
  Vec3 centre(4 * r.uniform() - 2, 4 * r.uniform() - 2, 4 * r.uniform() - 2);
  float spread = r.below(3) == 0 ? 0.01f : 2 * r.uniform();
  Vec3 axis = randomUnit(r);
  float coneAngle = r.below(3) == 0 ? 0.0f : kPi * r.uniform();
  std::vector<detail::Cluster> cl;
  for (int i = 0; i < n; ++i) {
    Light l;
    l.type = type;
    l.group = 0;
    l.position = centre + Vec3(r.uniform() - 0.5f, r.uniform() - 0.5f, r.uniform() - 0.5f) * spread;
    l.direction = type == LightType::Directional ? randomInCone(r, axis, coneAngle * 0.3f)
                                                 : randomInCone(r, axis, coneAngle);
    l.intensity = Color(r.uniform(), r.uniform(), r.uniform()) * (0.1f + 5 * r.uniform());
    c.set.lights.push_back(l);
    cl.push_back(detail::leafCluster(l, uint32_t(i)));
  }
  detail::Cluster acc = cl[0];
  bool withCone = type == LightType::Oriented || type == LightType::Spot;
  for (int i = 1; i < n; ++i) acc = detail::mergeClusters(acc, cl[size_t(i)], 0, i, withCone, 7);
  LightNode& nd = c.node;
  nd.lo = acc.lo;
  nd.hi = acc.hi;
  nd.axis = acc.axis;
  nd.cosHalfAngle = acc.cosHalfAngle;
  nd.intensity = acc.intensity;
  nd.rep = acc.rep;
  nd.left = 1;
  nd.sinHalfAngle = std::sqrt(std::max(0.0f, 1 - acc.cosHalfAngle * acc.cosHalfAngle));

  ShadingPoint& sp = c.sp;
  sp.p = r.below(5) == 0 ? centre : Vec3(6 * r.uniform() - 3, 6 * r.uniform() - 3, 6 * r.uniform() - 3);
  sp.n = randomUnit(r);
  Vec3 v = randomUnit(r);
  if (dot(v, sp.n) < 0) v = -v;
  sp.r = normalize(reflect(v, sp.n));
  sp.kd = Color(r.uniform(), r.uniform(), r.uniform());
  sp.ks = r.below(3) == 0 ? Color(0) : Color(r.uniform(), r.uniform(), r.uniform());
  const float shininess[] = {0, 0.2f, 1, 5, 25.6f, 128};
  sp.shininess = shininess[r.below(6)];
  return c;
}

Color trueSum(const Config& c) {
  Color s(0);
  for (const Light& l : c.set.lights) {
    Color mg;
    Vec3 wi;
    float d;
    if (lightContribution(l, c.set.groups[l.group], c.sp, mg, wi, d)) s += mg * l.intensity;
  }
  return s;
}

class BoundProperty : public ::testing::TestWithParam<LightType> {};

TEST_P(BoundProperty, BoundIsAtLeastTheTrueSum) {
  LightType type = GetParam();
  Rng r(12345, uint64_t(type));
  int nonZero = 0;
  for (int i = 0; i < 20000; ++i) {
    Config c = randomConfig(r, type);
    BoundFrames fr(c.sp);
    Color b = clusterBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color t = trueSum(c);
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_GE(b[ch] * (1 + 1e-5f) + 1e-12f, t[ch])
          << "config " << i << " channel " << ch << " type " << lightTypeName(type);
    nonZero += luminance(t) > 0;
  }
  // The random configurations must actually exercise lit cases.
  EXPECT_GT(nonZero, 2000);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, BoundProperty,
                         ::testing::Values(LightType::Omni, LightType::Oriented, LightType::Spot,
                                           LightType::Directional),
                         [](const auto& info) { return std::string(lightTypeName(info.param)); });

TEST(CosBoundBox, BoundsSampledDirections) {
  Rng r(3, 3);
  for (int i = 0; i < 5000; ++i) {
    Vec3 lo(4 * r.uniform() - 2, 4 * r.uniform() - 2, 4 * r.uniform() - 2);
    Vec3 hi = lo + Vec3(r.uniform(), r.uniform(), r.uniform()) * 2;
    Frame f = makeFrame(randomUnit(r));
    float b = cosBoundBox(f, lo, hi);
    for (int k = 0; k < 50; ++k) {
      Vec3 q = lo + (hi - lo) * Vec3(r.uniform(), r.uniform(), r.uniform());
      if (length2(q) == 0) continue;
      ASSERT_GE(b + 1e-6f, dot(normalize(q), f.w));
    }
  }
}

TEST(CosBoundBox, IsTightForAPointOnTheAxis) {
  Frame f = makeFrame(Vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(cosBoundBox(f, Vec3(0, 0, 2), Vec3(0, 0, 2)), 1.0f);
  EXPECT_FLOAT_EQ(cosBoundBox(f, Vec3(0, 0, -2), Vec3(0, 0, -1)), 0.0f);
  // A point at 45 degrees gives cos 45.
  EXPECT_NEAR(cosBoundBox(f, Vec3(1, 0, 1), Vec3(1, 0, 1)), std::sqrt(0.5f), 1e-6f);
}

TEST(ConeWiden, WidensByTheHalfAngle) {
  float c = coneWiden(std::cos(1.0f), std::cos(0.25f), std::sin(0.25f));
  EXPECT_NEAR(c, std::cos(0.75f), 1e-5f);
  EXPECT_EQ(coneWiden(0.9f, 0.5f, std::sqrt(0.75f)), 1.0f);
  EXPECT_EQ(coneWiden(-0.5f, -1.0f, 0.0f), 1.0f);
}

TEST(ConeUnion, ContainsBothCones) {
  Rng r(9, 9);
  for (int i = 0; i < 2000; ++i) {
    Vec3 a = randomUnit(r), b = randomUnit(r);
    float ca = std::cos(kPi * r.uniform() * 0.5f), cb = std::cos(kPi * r.uniform() * 0.5f);
    Vec3 axis;
    float cu;
    coneUnion(a, ca, b, cb, axis, cu);
    for (int k = 0; k < 20; ++k) {
      Vec3 da = randomInCone(r, a, std::acos(ca));
      Vec3 db = randomInCone(r, b, std::acos(cb));
      ASSERT_GE(dot(da, axis), cu - 1e-4f);
      ASSERT_GE(dot(db, axis), cu - 1e-4f);
    }
  }
}

}  // namespace
}  // namespace lc::lightcuts

namespace lc::lightcuts {
namespace {

// The lower bound never exceeds the true unshadowed sum (and so brackets it with the upper).
TEST_P(BoundProperty, LowerBoundIsAtMostTheTrueSum) {
  LightType type = GetParam();
  Rng r(777, uint64_t(type));
  int positive = 0;
  for (int i = 0; i < 20000; ++i) {
    Config c = randomConfig(r, type);
    BoundFrames fr(c.sp);
    Color lb = clusterLowerBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color ub = clusterBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color t = trueSum(c);
    for (int ch = 0; ch < 3; ++ch) {
      ASSERT_LE(lb[ch], t[ch] * (1 + 1e-5f) + 1e-12f) << "config " << i << " type " << lightTypeName(type);
      ASSERT_LE(lb[ch], ub[ch] + 1e-12f);
    }
    positive += luminance(lb) > 0;
  }
  EXPECT_GT(positive, 500);  // and is not trivially zero
}

}  // namespace
}  // namespace lc::lightcuts
