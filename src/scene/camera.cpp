#include "scene/camera.h"

#include <cmath>

namespace lc::scene {

Camera Camera::fromDesc(const io::CameraDesc& c, float imageAspect) {
  Camera cam;
  cam.eye = c.position;
  // normalizeScaled: huge or tiny components (viewdir = (0,0,-1e20)) would overflow or
  // underflow the squared length.
  cam.look = normalizeScaled(c.viewDir);
  // Gram-Schmidt: `up` need not be perpendicular to the view direction.
  Vec3 r = normalize(cross(cam.look, normalizeScaled(c.upDir)));
  Vec3 u = cross(r, cam.look);
  cam.aspect = c.aspectRatio ? *c.aspectRatio : imageAspect;
  float halfH = std::tan(c.fovDegrees * kPi / 360.0f);
  cam.up = u * halfH;
  cam.right = r * (halfH * cam.aspect);
  return cam;
}

}  // namespace lc::scene
