// Pinhole camera of the course ray tracer: an image plane at distance 1 whose height is
// 2*tan(fov/2) and whose width is aspect times that.
#pragma once

#include "core/math.h"
#include "io/scene_desc.h"

namespace lc::scene {

struct Camera {
  Vec3 eye{0, 0, 0};
  Vec3 look{0, 0, -1};  // unit view direction
  Vec3 right{1, 0, 0};  // half-width of the image plane, pointing right
  Vec3 up{0, 1, 0};     // half-height of the image plane, pointing up
  float aspect = 1;

  // From a scene's camera block; `aspect` is width/height of the image unless the scene
  // fixes it (CameraDesc::aspectRatio).
  static Camera fromDesc(const io::CameraDesc& c, float imageAspect);

  // Direction through image coordinates (sx, sy) in [0,1]^2, (0,0) the top-left corner.
  Vec3 direction(float sx, float sy) const {
    return look + right * (2 * sx - 1) + up * (1 - 2 * sy);
  }
};

}  // namespace lc::scene
