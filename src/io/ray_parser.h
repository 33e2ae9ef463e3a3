// Reader for the SBT .ray scene format (see docs/SCENE_FORMAT.md). Produces a SceneDesc;
// every error is an lc::Error carrying file:line:column and what was expected.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/progress.h"
#include "core/limits.h"
#include "io/scene_desc.h"

namespace lc::io {

struct ParseOptions {
  // Unknown keywords and blocks are skipped with a warning (SceneDesc::warnings)
  // instead of being errors.
  bool lenient = false;
  Limits limits;
  // `emission = Le` (COMP4411): point lights per unit of world area of the object light it
  // makes (--emission-density).
  float emissionDensity = 1;
  // --default-attenuation A,B,C: the constant, linear and quadratic coefficients of every
  // point_light and spot_light that sets none of the three (unset: 0, 0, 1).
  std::optional<std::array<float, 3>> defaultAttenuation;
  // Called with the share of the text read (core/progress.h): a 40 MB scene takes seconds.
  ProgressFn progress = {};
};

// Parses a .ray file. Relative paths inside (textures, obj_mesh) resolve against its directory.
SceneDesc parseRayFile(const std::string& path, const ParseOptions& options = {});

// Parses .ray text; `name` is used in error messages and `baseDir` resolves relative paths.
SceneDesc parseRayString(std::string_view text, const std::string& name,
                         const std::string& baseDir, const ParseOptions& options = {});

}  // namespace lc::io
