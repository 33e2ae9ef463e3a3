// Writes a SceneDesc back as .ray text (used by obj2ray and by parser round-trip tests).
// Meshes are written in world space when `bakeTransforms` is true, otherwise wrapped in
// a `transform(...)` of their object-to-world matrix.
#pragma once

#include <string>

#include "io/scene_desc.h"

namespace lc::io {

struct RayWriteOptions {
  bool bakeTransforms = false;
  // Texture paths are written relative to this directory when possible ("" = as stored).
  std::string relativeTo;
};

std::string writeRayString(const SceneDesc& scene, const RayWriteOptions& options = {});
// Atomic write; throws lc::Error when the file cannot be written.
void writeRayFile(const std::string& path, const SceneDesc& scene, const RayWriteOptions& options = {});

}  // namespace lc::io
