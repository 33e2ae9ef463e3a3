// Every scene shipped in scenes/ loads (parse, geometry, object lights, VPLs) and renders
// a small image with finite, not-all-black pixels.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/scene_loader.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lc::app {
namespace {

std::vector<std::string> shippedScenes() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(testing::sourceDir() + "/scenes"))
    if (e.path().extension() == ".ray") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ShippedScenes, LoadAndRender) {
  auto scenes = shippedScenes();
  ASSERT_GE(scenes.size(), 7u);
  for (const std::string& path : scenes) {
    SCOPED_TRACE(path);
    LoadOptions o;
    o.vplCount = 500;  // keep it quick: the scenes' own instant_radiosity blocks ask for more
    LoadedScene ls = loadScene(path, o);
    ASSERT_GT(ls.scene->lights().size(), 0u);
    scene::Scene& s = *ls.scene;
    s.setCamera(scene::Camera::fromDesc(s.cameraDesc(), 1.0f));
    lightcuts::LightForest f = lightcuts::buildLightForest(s.lights());
    auto ev = lightcuts::makeLightcuts(s.lights(), f, {});
    render::RenderOptions ro;
    ro.width = ro.height = 16;
    render::RenderResult r = render::render(s, *ev, ro);
    double sum = 0;
    for (const Color& c : r.image.pixels) {
      ASSERT_TRUE(isFinite(c));
      sum += luminance(c);
    }
    EXPECT_GT(sum, 0.0);
  }
}

}  // namespace
}  // namespace lc::app
