// Light sets, shading points and tree helpers shared by the lightcuts tests.
#pragma once

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "lightcuts/cluster.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/shading.h"
#include "core/light.h"

namespace lc::lightcuts::test_lights {

// n lights of one kind, 2 to 3 units above a 4 x 4 square around the origin, pointing down.
inline LightSet cloud(size_t n, LightType type, uint64_t seed) {
  LightSet s;
  s.groups.push_back(LightGroup{});
  Rng r(seed, 2);
  for (size_t i = 0; i < n; ++i) {
    Light l;
    l.type = type;
    l.position = Vec3(r.uniform() * 4 - 2, 2 + r.uniform(), r.uniform() * 4 - 2);
    l.direction = normalize(Vec3(r.uniform() - 0.5f, -1, r.uniform() - 0.5f));
    l.intensity = Color(r.uniform(), r.uniform(), r.uniform()) * 0.01f;
    s.lights.push_back(l);
  }
  return s;
}

// A Phong receiver at p facing up.
inline ShadingPoint point(Vec3 p) {
  ShadingPoint sp;
  sp.p = p;
  sp.n = Vec3(0, 1, 0);
  sp.r = normalize(Vec3(0.3f, 1, 0.1f));
  sp.kd = Color(0.7f, 0.6f, 0.5f);
  sp.ks = Color(0.3f);
  sp.shininess = 10;
  return sp;
}

// Lights under node r, counted leaf by leaf.
inline uint32_t leafCount(const LightTree& t, NodeRef r) {
  if (isLeafRef(r)) return 1;
  const LightNode& n = t.nodes[r];
  return leafCount(t, n.left(r)) + leafCount(t, n.right(r));
}
// The root's two children.
inline NodeRef rootLeft(const LightTree& t) { return t.nodes[t.root].left(t.root); }
inline NodeRef rootRight(const LightTree& t) { return t.nodes[t.root].right(t.root); }

// ---- random clusters for the property tests (bounds, estimates) ----

inline Vec3 randomUnit(Rng& r) {
  for (;;) {
    Vec3 v(2 * r.uniform() - 1, 2 * r.uniform() - 1, 2 * r.uniform() - 1);
    float l2 = length2(v);
    if (l2 > 1e-4f && l2 <= 1) return v / std::sqrt(l2);
  }
}

// A direction within `angle` radians of `axis`.
inline Vec3 randomInCone(Rng& r, const Vec3& axis, float angle) {
  float cosT = 1 - r.uniform() * (1 - std::cos(angle));
  float sinT = std::sqrt(std::max(0.0f, 1 - cosT * cosT));
  float phi = 2 * kPi * r.uniform();
  Vec3 u, v;
  orthonormalBasis(axis, u, v);
  return normalize(axis * cosT + u * (sinT * std::cos(phi)) + v * (sinT * std::sin(phi)));
}

inline LightGroup randomGroup(Rng& r, LightType type) {
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
inline Config randomConfig(Rng& r, LightType type) {
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
  detail::setNodeFromCluster(c.node, acc);

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

inline Color trueSum(const Config& c) {
  Color s(0);
  for (const Light& l : c.set.lights) {
    Color mg;
    Vec3 wi;
    float d;
    if (lightContribution(l, c.set.groups[l.group], c.sp, mg, wi, d)) s += mg * l.intensity;
  }
  return s;
}

}  // namespace lc::lightcuts::test_lights
