// OBJ/MTL input through tinyobjloader.
#pragma once

#include <string>
#include <vector>

#include "core/limits.h"
#include "core/progress.h"
#include "io/scene_desc.h"

namespace lc::io {

// One OBJ file as a mesh plus the materials its faces use.
struct ObjData {
  MeshDesc mesh;                        // triangleMaterials index into `materials`
  std::vector<MaterialDesc> materials;  // from the MTL (a grey default when none)
  std::vector<std::string> warnings;
  Bounds3 bounds;
};

// Loads `path`. `referredFrom` is the location of the `obj_mesh` that named it (or empty)
// so that a missing file is reported where it was asked for. `base` is the material that
// MTL materials start from (the current default material in a .ray file).
// `progress` (core/progress.h), when given, is told the share of the file parsed.
ObjData loadObj(const std::string& path, const SourceLoc& referredFrom, const MaterialDesc& base,
                const Limits& limits, const ProgressFn& progress = {});

// A whole scene from an OBJ file: the mesh, its materials, and, because an OBJ brings
// neither, a default camera framing its bounds and a default light rig. `description`
// receives the camera and lights in .ray syntax so a user can copy them.
SceneDesc loadObjScene(const std::string& path, const Limits& limits, std::string* description,
                       const ProgressFn& progress = {});

// Writes a .ray equivalent of an OBJ scene (obj2ray).
void writeRayFromObj(const std::string& objPath, const std::string& outPath, const Limits& limits);

}  // namespace lc::io
