// `lightcuts info`: what a scene holds, without rendering it.
#include <fmt/format.h>

#include <map>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/scene_loader.h"
#include "app/scene_options.h"
#include "app/summary.h"

namespace lc::app {

namespace {

struct InfoArgs {
  std::string scene;
  bool json = false;
  LoadOptions load;
};

const char* shapeName(io::ShapeKind k) {
  switch (k) {
    case io::ShapeKind::Sphere: return "sphere";
    case io::ShapeKind::Box: return "box";
    case io::ShapeKind::Square: return "square";
    case io::ShapeKind::Cylinder: return "cylinder";
    case io::ShapeKind::Cone: return "cone";
    case io::ShapeKind::Mesh: return "trimesh";
  }
  return "?";
}

int runInfo(InfoArgs& a) {
  a.load.quiet = true;
  a.load.occluders = false;  // nothing here asks whether shadow rays are clear
  a.load.planarFaces = false;
  LoadedScene ls = loadScene(a.scene, a.load);
  const scene::Scene& s = *ls.scene;
  std::map<std::string, int> shapes;
  for (const auto& sh : s.shapes()) ++shapes[shapeName(sh.kind)];
  const LightSet& L = s.lights();
  nlohmann::json j;
  j["scene"] = a.scene;
  j["objects"] = s.shapes().size();
  j["objects_by_kind"] = shapes;
  j["triangles"] = s.triangleCount();
  j["materials"] = s.materials().size();
  j["lights"] = lightCountsJson(L);
  j["ambient"] = {s.ambient().x, s.ambient().y, s.ambient().z};
  const Bounds3& b = s.bounds();
  j["bounds"] = {{"min", {b.lo.x, b.lo.y, b.lo.z}}, {"max", {b.hi.x, b.hi.y, b.hi.z}}};
  j["object_lights"] = objectLightsJson(ls.objectLights);
  j["environment_lights"] = environmentLightsJson(ls.environmentLights);
  j["vpls"] = ls.vpls.vpls;
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("scene      {}\n", a.scene);
  std::string kinds;
  for (const auto& [k, n] : shapes) kinds += fmt::format("{}{} {}", kinds.empty() ? "" : ", ", n, k);
  fmt::print("objects    {} ({})\n", s.shapes().size(), kinds);
  fmt::print("triangles  {}\n", s.triangleCount());
  fmt::print("materials  {}\n", s.materials().size());
  fmt::print("lights     {}\n", lightCountsLine(L));
  fmt::print("ambient    ({}, {}, {})\n", s.ambient().x, s.ambient().y, s.ambient().z);
  if (!b.empty())
    fmt::print("bounds     ({:.4g}, {:.4g}, {:.4g}) .. ({:.4g}, {:.4g}, {:.4g})\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  for (const auto& o : ls.objectLights)
    fmt::print("object light  #{} {}: {} lights over area {:.4g}, power ({:.4g}, {:.4g}, {:.4g})\n", o.shape,
               o.name.empty() ? "(unnamed)" : o.name, o.lights, o.area, o.power.x, o.power.y, o.power.z);
  for (const auto& e : ls.environmentLights)
    fmt::print("environment  {}: {} directional lights, power ({:.4g}, {:.4g}, {:.4g})\n", e.what, e.lights, e.power.x,
               e.power.y, e.power.z);
  if (ls.vpls.vpls) fmt::print("vpls       {} from {} paths\n", ls.vpls.vpls, ls.vpls.paths);
  for (const std::string& w : ls.warnings) fmt::print("warning    {}\n", w);
  return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  CLI::App* c = app.add_subcommand("info", "Describe a scene: objects, triangles, materials, lights by kind, bounds");
  c->add_option("scene", a->scene, "Scene file (.ray or .obj)")->required();
  c->add_flag("--json", a->json, "Print JSON");
  addSceneOptions(*c, a->load);
  c->callback([a] {
    if (!parseOnly()) exitStatus() = runInfo(*a);
  });
}

}  // namespace lc::app
