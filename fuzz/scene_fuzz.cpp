// libFuzzer target: scene loading end to end: parse, Scene::build (textures, meshes,
// Embree), object lights and VPLs, all on a tiny budget.
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::loadScene(data, size, LC_FUZZ_DATA_DIR);
  } catch (const lc::Error&) {
  }
  return 0;
}
