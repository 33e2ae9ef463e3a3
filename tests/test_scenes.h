// Small scenes shared by tests in more than one folder.
#pragma once

#include <fmt/format.h>

#include <memory>
#include <string>

#include "io/ray_parser.h"
#include "scene/scene.h"

namespace lc::testing {

// A closed box of albedo `a`, 20 units wide (every wall farther than 1 from the light, so
// min(1, 1/d^2) is exactly 1/d^2), with one point light of intensity I near its centre.
inline std::unique_ptr<scene::Scene> closedBox(float a, float I) {
  std::string text = fmt::format(R"(SBT-raytracer 1.0
point_light {{ position = (0.3, -0.2, 0.1); colour = ({}, {}, {}); }}
scale(20, box {{ material = {{ diffuse = ({}, {}, {}); }}; }})
)", I, I, I, a, a, a);
  return scene::Scene::build(io::parseRayString(text, "box.ray", ""));
}

// One primitive of `kind` under object-to-world m, with the given cylinder/cone shape.
inline io::ObjectDesc primitive(io::ShapeKind kind, const Mat4& m, float height = 1.5f, float bottomRadius = 1,
                                float topRadius = 0.5f) {
  io::ObjectDesc o;
  o.kind = kind;
  o.transform = m;
  o.height = height;
  o.bottomRadius = bottomRadius;
  o.topRadius = topRadius;
  return o;
}

}  // namespace lc::testing
