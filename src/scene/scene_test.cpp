// Ray-primitive intersection for every primitive, canonical and transformed.
#include "scene/scene.h"

#include <gtest/gtest.h>

#include "core/rng.h"

namespace lc::scene {
namespace {

using io::ShapeKind;

std::unique_ptr<Scene> oneShape(ShapeKind kind, const Mat4& m = Mat4::identity(), bool capped = true) {
  io::SceneDesc d;
  d.materials.emplace_back();
  io::ObjectDesc o;
  o.kind = kind;
  o.transform = m;
  o.capped = capped;
  o.height = 2;
  o.bottomRadius = 1;
  o.topRadius = 0.5f;
  d.objects.push_back(o);
  return Scene::build(d);
}

Hit shoot(const Scene& s, Vec3 o, Vec3 d, bool expectHit = true) {
  Hit h;
  bool hit = s.intersect(Ray{o, normalize(d), 0, kInf}, h);
  EXPECT_EQ(hit, expectHit) << "ray from " << o.x << "," << o.y << "," << o.z;
  return h;
}

void expectVec(const Vec3& a, const Vec3& b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(Intersect, Sphere) {
  auto s = oneShape(ShapeKind::Sphere);
  Hit h = shoot(*s, Vec3(0, 0, 5), Vec3(0, 0, -1));
  EXPECT_NEAR(h.t, 4, 1e-5);
  expectVec(h.ng, Vec3(0, 0, 1));
  EXPECT_TRUE(h.frontFace);
  shoot(*s, Vec3(0, 1.01f, 5), Vec3(0, 0, -1), false);
  // From inside: the far side, back face, normal flipped toward the ray.
  Hit in = shoot(*s, Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(in.t, 1, 1e-5);
  EXPECT_FALSE(in.frontFace);
  expectVec(in.ng, Vec3(-1, 0, 0));
}

TEST(Intersect, ScaledAndTranslatedSphereIsAnEllipsoid) {
  auto s = oneShape(ShapeKind::Sphere, Mat4::translate(1, 2, 3) * Mat4::scale(2, 1, 0.5f));
  Hit h = shoot(*s, Vec3(10, 2, 3), Vec3(-1, 0, 0));
  EXPECT_NEAR(h.p.x, 3, 1e-4);
  expectVec(h.ng, Vec3(1, 0, 0));
  Hit top = shoot(*s, Vec3(1, 2, 10), Vec3(0, 0, -1));
  EXPECT_NEAR(top.p.z, 3.5f, 1e-4);
  // Off-axis point: the normal follows the inverse transpose, not the local normal.
  Vec3 local = normalize(Vec3(1, 1, 1));
  Vec3 world = Vec3(1, 2, 3) + Vec3(2 * local.x, local.y, 0.5f * local.z);
  Hit g = shoot(*s, world + Vec3(0, 0, 5), Vec3(0, 0, -1));
  expectVec(g.p, world, 1e-3f);
  expectVec(g.ng, normalize(Vec3(local.x / 2, local.y, 2 * local.z)), 1e-3f);
}

TEST(Intersect, BoxFaces) {
  auto s = oneShape(ShapeKind::Box);
  const Vec3 dirs[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Vec3& d : dirs) {
    Hit h = shoot(*s, d * -3.0f, d);
    EXPECT_NEAR(h.t, 2.5f, 1e-5);
    expectVec(h.ng, -d);
  }
  // A rotated box: the corner direction hits at distance 3 - sqrt(3)/2.
  auto r = oneShape(ShapeKind::Box, Mat4::rotate(0, 0, 1, kPi / 4));
  Hit h = shoot(*r, Vec3(3, 0, 0), Vec3(-1, 0, 0));
  EXPECT_NEAR(h.p.x, std::sqrt(0.5f), 1e-4);
}

TEST(Intersect, SquareIsOneSidedGeometryTwoSidedHits) {
  auto s = oneShape(ShapeKind::Square);
  Hit a = shoot(*s, Vec3(0.2f, 0.3f, 2), Vec3(0, 0, -1));
  EXPECT_NEAR(a.t, 2, 1e-5);
  EXPECT_TRUE(a.frontFace);
  EXPECT_NEAR(a.uv.x, 0.7f, 1e-5);
  EXPECT_NEAR(a.uv.y, 0.8f, 1e-5);
  Hit b = shoot(*s, Vec3(0.2f, 0.3f, -2), Vec3(0, 0, 1));
  EXPECT_FALSE(b.frontFace);
  expectVec(b.ng, Vec3(0, 0, -1));
  shoot(*s, Vec3(0.6f, 0, 2), Vec3(0, 0, -1), false);
}

TEST(Intersect, CylinderBodyAndCaps) {
  auto s = oneShape(ShapeKind::Cylinder);
  Hit side = shoot(*s, Vec3(5, 0, 0.5f), Vec3(-1, 0, 0));
  EXPECT_NEAR(side.t, 4, 1e-5);
  expectVec(side.ng, Vec3(1, 0, 0));
  Hit cap = shoot(*s, Vec3(0.3f, 0, 5), Vec3(0, 0, -1));
  EXPECT_NEAR(cap.p.z, 1, 1e-5);
  expectVec(cap.ng, Vec3(0, 0, 1));
  auto open = oneShape(ShapeKind::Cylinder, Mat4::identity(), false);
  Hit through = shoot(*open, Vec3(0.3f, 0, 5), Vec3(0, 0, -1), false);
  (void)through;
  // Looking into an open tube from above at an angle hits the inside wall.
  Hit inside = shoot(*open, Vec3(0, 0, 1.5f), normalize(Vec3(1, 0, -1)));
  EXPECT_FALSE(inside.frontFace);
}

TEST(Intersect, ConeWithTwoRadii) {
  auto s = oneShape(ShapeKind::Cone);  // height 2, radius 1 at z=0, 0.5 at z=2
  Hit mid = shoot(*s, Vec3(5, 0, 1), Vec3(-1, 0, 0));
  EXPECT_NEAR(mid.p.x, 0.75f, 1e-4);
  // Slant normal: gradient of x^2+y^2-(1 - z/4)^2 at (0.75,0,1) ~ (0.75, 0, 0.1875).
  expectVec(mid.ng, normalize(Vec3(0.75f, 0, 0.1875f)), 1e-4f);
  Hit top = shoot(*s, Vec3(0.2f, 0, 5), Vec3(0, 0, -1));
  EXPECT_NEAR(top.p.z, 2, 1e-5);
  Hit bottom = shoot(*s, Vec3(0.9f, 0, -5), Vec3(0, 0, 1));
  EXPECT_NEAR(bottom.p.z, 0, 1e-5);
  shoot(*s, Vec3(0.8f, 0, 5), Vec3(0, 0, -1));  // hits the slanted side
}

TEST(Intersect, ShearedTransformKeepsNormalsPerpendicular) {
  Mat4 m = Mat4::identity();
  m.m[0][2] = 0.7;  // x += 0.7 z
  auto s = oneShape(ShapeKind::Box, m);
  Rng r(5, 5);
  for (int i = 0; i < 200; ++i) {
    Vec3 o(4 * r.uniform() - 2, 4 * r.uniform() - 2, 5);
    Vec3 d = normalize(Vec3(r.uniform() - 0.5f, r.uniform() - 0.5f, -1));
    Hit h;
    if (!s->intersect(Ray{o, d, 0, kInf}, h)) continue;
    // The point satisfies the box in local space, on a face.
    Mat4 inv;
    ASSERT_TRUE(m.inverseAffine(inv));
    Vec3 lp = inv.point(h.p);
    EXPECT_NEAR(maxComponent(vabs(lp)), 0.5f, 1e-4f);
  }
}

TEST(Intersect, TriangleMeshWithNormalsAndUvs) {
  io::SceneDesc d;
  d.materials.emplace_back();
  io::MeshDesc m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  m.normals = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  m.uvs = {{0, 0}, {1, 0}, {0, 1}};
  d.meshes.push_back(m);
  io::ObjectDesc o;
  o.kind = ShapeKind::Mesh;
  o.mesh = 0;
  o.transform = Mat4::translate(0, 0, 1) * Mat4::scale(2, 2, 2);
  d.objects.push_back(o);
  auto s = Scene::build(d);
  Hit h = shoot(*s, Vec3(0.5f, 0.5f, 5), Vec3(0, 0, -1));
  EXPECT_NEAR(h.t, 4, 1e-5);
  EXPECT_NEAR(h.uv.x, 0.25f, 1e-5);
  EXPECT_NEAR(h.uv.y, 0.25f, 1e-5);
  expectVec(h.ng, Vec3(0, 0, 1));
  // Interpolated shading normal leans toward +x and +y.
  EXPECT_GT(h.ns.x, 0.05f);
  EXPECT_GT(h.ns.y, 0.05f);
}

TEST(Scene, SingularTransformIsAnError) {
  io::SceneDesc d;
  d.materials.emplace_back();
  io::ObjectDesc o;
  o.kind = ShapeKind::Sphere;
  o.transform = Mat4::scale(1, 0, 1);
  o.loc = SourceLoc{"x.ray", 3, 4};
  d.objects.push_back(o);
  try {
    Scene::build(d);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.ray:3:4"), std::string::npos);
  }
}

// Light::group is 16 bits: the 65,536th distinct attenuation is an error at its light, not
// a wrapped index that silently gives it another light's model.
TEST(Scene, TooManyDistinctLightGroupsIsAnErrorAtTheLight) {
  io::SceneDesc d;
  for (int i = 0; i < 65536; ++i) {
    io::LightDesc l;
    l.attenConstant = 0.1f + float(i) * 1e-5f;
    l.loc = SourceLoc{"x.ray", i + 1, 1};
    d.lights.push_back(l);
  }
  d.lights.back().attenConstant = d.lights.front().attenConstant;  // a group already seen: fine
  EXPECT_NO_THROW(Scene::build(d));
  d.lights.back().attenConstant = 0.05f;  // the 65,536th distinct one
  try {
    Scene::build(d);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.ray:65536:1"), std::string::npos) << e.what();
  }
}

TEST(Scene, TransmittanceMultipliesThroughGlass) {
  io::SceneDesc d;
  io::MaterialDesc glass;
  glass.transmissive.value = Color(0.5f, 0.8f, 1.0f);
  d.materials.push_back(glass);
  io::ObjectDesc o;
  o.kind = ShapeKind::Sphere;
  d.objects.push_back(o);
  auto s = Scene::build(d);
  ASSERT_TRUE(s->hasTransmissive());
  // Through both surfaces of the sphere: kt squared.
  Color t = s->transmittance(Vec3(-5, 0, 0), Vec3(1, 0, 0), 10);
  expectVec(t, Color(0.25f, 0.64f, 1.0f), 1e-5f);
  Color miss = s->transmittance(Vec3(-5, 3, 0), Vec3(1, 0, 0), 10);
  expectVec(miss, Color(1), 0);
}

TEST(Camera, CentreRayLooksAlongViewDirection) {
  io::CameraDesc c;
  c.position = Vec3(1, 2, 3);
  c.viewDir = Vec3(0, 0, 1);
  c.upDir = Vec3(0, 1, 0);
  c.fovDegrees = 90;
  Camera cam = Camera::fromDesc(c, 2.0f);
  expectVec(normalize(cam.direction(0.5f, 0.5f)), Vec3(0, 0, 1));
  // fov 90: the top edge is at 45 degrees; aspect 2 doubles the width.
  Vec3 top = cam.direction(0.5f, 0);
  EXPECT_NEAR(top.y / top.z, 1, 1e-5);
  Vec3 right = cam.direction(1, 0.5f);
  EXPECT_NEAR(std::fabs(right.x / right.z), 2, 1e-5);
}

TEST(Camera, HugeViewAndUpDirectionsAreNormalisedSafely) {
  // Issue 23 #10: the squared length of (0,0,-1e20) overflows a float.
  io::CameraDesc c;
  c.viewDir = Vec3(0, 0, -1e20f);
  c.upDir = Vec3(0, 1e30f, 0);
  c.fovDegrees = 90;
  Camera cam = Camera::fromDesc(c, 1.0f);
  expectVec(normalize(cam.direction(0.5f, 0.5f)), Vec3(0, 0, -1));
  expectVec(cam.up, Vec3(0, 1, 0));
  expectVec(cam.right, Vec3(1, 0, 0));
}

TEST(Scene, HugeDirectionalLightDirectionIsNormalised) {
  // Issue 23 #10: (1e20,1e20,-1e20) normalised to zero and the scene rendered black.
  io::SceneDesc d;
  d.materials.emplace_back();
  for (Vec3 dir : {Vec3(1e20f, 1e20f, -1e20f), Vec3(1e-30f, 1e-30f, -1e-30f)}) {
    for (io::LightKind kind : {io::LightKind::Directional, io::LightKind::Spot}) {
      io::LightDesc l;
      l.kind = kind;
      l.direction = dir;
      d.lights = {l};
      auto s = Scene::build(d);
      ASSERT_EQ(s->lights().lights.size(), 1u);
      float k = 1 / std::sqrt(3.0f);
      expectVec(s->lights().lights[0].direction, Vec3(k, k, -k), 1e-5f);
    }
  }
}

}  // namespace
}  // namespace lc::scene
