// Resource limits on every count that input controls. Each is checked before memory is
// allocated; the error names the limit and the command-line flag that raises it.
#pragma once

#include <cstdint>
#include <string>

namespace lc {

struct Limits {
  uint64_t maxLights = 20'000'000;      // --max-lights: object lights + VPLs + scene lights
  uint64_t maxTriangles = 50'000'000;   // --max-triangles: all meshes together
  uint64_t maxVertices = 50'000'000;    // --max-triangles also bounds vertices (same flag)
  uint64_t maxImagePixels = 100'000'000;   // --max-image-pixels: width * height
  uint64_t maxTexturePixels = 268'435'456; // --max-texture-pixels: per texture (16384^2)
  int maxNesting = 1000;                // --max-nesting: nested transforms/groups/comments
  uint64_t maxObjects = 5'000'000;      // --max-objects: primitives and materials in a .ray file
  uint64_t maxVpls = 10'000'000;        // --max-vpls
  uint64_t maxFileBytes = 2'000'000'000;  // scene/OBJ file size
};

}  // namespace lc
