// Light sets, shading points and tree helpers shared by the lightcuts tests.
#pragma once

#include "core/rng.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/shading.h"
#include "scene/light.h"

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

// Lights under node i.
inline uint32_t leafCount(const LightTree& t, uint32_t i) {
  const LightNode& n = t.nodes[i];
  return n.isLeaf() ? 1u : leafCount(t, n.left) + leafCount(t, n.left + 1);
}

}  // namespace lc::lightcuts::test_lights
