// Texture coordinates on the quadrics (the parametrisations at the top of shape.h) at known
// points, directly and through Scene::intersect under transforms (uvs stay in the local
// frame), and textures looked up through a scene (orientation, sRGB option).
#include <gtest/gtest.h>

#include <cmath>

#include "io/image.h"
#include "scene/scene.h"
#include "scene/shape.h"
#include "test_scenes.h"
#include "test_util.h"

namespace lc::scene {
namespace {

using io::ShapeKind;

constexpr float kTol = 1e-5f;

Shape shapeOf(ShapeKind kind, float height = 1, float bottomRadius = 1, float topRadius = 0) {
  Shape s;
  s.kind = kind;
  s.height = height;
  s.bottomRadius = bottomRadius;
  s.topRadius = topRadius;
  return s;
}

void expectUv(Vec2 got, float u, float v, float tol = kTol) {
  EXPECT_NEAR(got.x, u, tol);
  EXPECT_NEAR(got.y, v, tol);
}

// Hits land on texel centres only up to rounding, so bilinear weights are ~0, not 0.
void expectColor(const Color& got, const Color& want, float tol = 1e-4f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(QuadricUv, SpherePolesAndEquator) {
  Shape s = shapeOf(ShapeKind::Sphere);
  // v = 0.5 + latitude / pi: 0 at the south pole (z = -1), 1 at the north pole.
  EXPECT_NEAR(quadricUv(s, Vec3(0, 0, -1), 0).y, 0.0f, kTol);
  EXPECT_NEAR(quadricUv(s, Vec3(0, 0, 1), 0).y, 1.0f, kTol);
  // u = longitude / 2 pi about z, from +x towards +y.
  expectUv(quadricUv(s, Vec3(1, 0, 0), 0), 0.0f, 0.5f);
  expectUv(quadricUv(s, Vec3(0, 1, 0), 0), 0.25f, 0.5f);
  expectUv(quadricUv(s, Vec3(-1, 0, 0), 0), 0.5f, 0.5f);
  expectUv(quadricUv(s, Vec3(0, -1, 0), 0), 0.75f, 0.5f);
  // Latitude 45 degrees north at longitude 45 degrees.
  float c = std::sqrt(0.5f);
  expectUv(quadricUv(s, Vec3(0.5f, 0.5f, c), 0), 0.125f, 0.75f);
  // u stays in [0, 1) just below the seam (y slightly negative).
  Vec2 seam = quadricUv(s, Vec3(1, -1e-4f, 0), 0);
  EXPECT_GE(seam.x, 0.99f);
  EXPECT_LT(seam.x, 1.0f);
  // Only the direction counts: a point off the unit sphere (rounding) reads the same.
  expectUv(quadricUv(s, Vec3(0, 1.001f, 0), 0), 0.25f, 0.5f);
  EXPECT_NEAR(quadricUv(s, Vec3(0, 0, 1.001f), 0).y, 1.0f, kTol);
}

TEST(QuadricUv, BoxFaces) {
  Shape s = shapeOf(ShapeKind::Box);
  // part = 2 * axis + (1 for the + face). Each face maps two in-plane coordinates + 0.5,
  // right-handed about its outward normal (u x v = n), so no face is mirrored:
  //   x faces (parts 0, 1): (-y | y, z);  y faces (2, 3): (x | -x, z);  z faces (4, 5): (-x | x, y).
  const Vec3 p(0.3f, -0.2f, 0.1f);  // an interior point; the fixed coordinate is unused
  expectUv(quadricUv(s, Vec3(-0.5f, p.y, p.z), 0), 0.5f - p.y, p.z + 0.5f);
  expectUv(quadricUv(s, Vec3(0.5f, p.y, p.z), 1), p.y + 0.5f, p.z + 0.5f);
  expectUv(quadricUv(s, Vec3(p.x, -0.5f, p.z), 2), p.x + 0.5f, p.z + 0.5f);
  expectUv(quadricUv(s, Vec3(p.x, 0.5f, p.z), 3), 0.5f - p.x, p.z + 0.5f);
  expectUv(quadricUv(s, Vec3(p.x, p.y, -0.5f), 4), 0.5f - p.x, p.y + 0.5f);
  expectUv(quadricUv(s, Vec3(p.x, p.y, 0.5f), 5), p.x + 0.5f, p.y + 0.5f);
  // Face corners span the whole [0, 1]^2.
  expectUv(quadricUv(s, Vec3(-0.5f, -0.5f, 0.5f), 5), 0, 0);
  expectUv(quadricUv(s, Vec3(0.5f, 0.5f, 0.5f), 5), 1, 1);
}

TEST(QuadricUv, SquareCorners) {
  Shape s = shapeOf(ShapeKind::Square);
  expectUv(quadricUv(s, Vec3(-0.5f, -0.5f, 0), 0), 0, 0);
  expectUv(quadricUv(s, Vec3(0.5f, -0.5f, 0), 0), 1, 0);
  expectUv(quadricUv(s, Vec3(-0.5f, 0.5f, 0), 0), 0, 1);
  expectUv(quadricUv(s, Vec3(0.5f, 0.5f, 0), 0), 1, 1);
  expectUv(quadricUv(s, Vec3(0, 0, 0), 0), 0.5f, 0.5f);
}

TEST(QuadricUv, CylinderBodyAndCaps) {
  Shape s = shapeOf(ShapeKind::Cylinder);
  // Body (part 0): u = angle / 2 pi about z from +x, v = z.
  expectUv(quadricUv(s, Vec3(1, 0, 0), 0), 0, 0);
  expectUv(quadricUv(s, Vec3(0, 1, 0.5f), 0), 0.25f, 0.5f);
  expectUv(quadricUv(s, Vec3(-1, 0, 1), 0), 0.5f, 1);
  expectUv(quadricUv(s, Vec3(0, -1, 0.25f), 0), 0.75f, 0.25f);
  // Caps (1 at z = 0, 2 at z = 1): the disk's bounding square mapped to [0, 1]^2.
  for (int part : {1, 2}) {
    float z = part == 1 ? 0.0f : 1.0f;
    expectUv(quadricUv(s, Vec3(0, 0, z), part), 0.5f, 0.5f);
    expectUv(quadricUv(s, Vec3(1, 0, z), part), 1, 0.5f);
    expectUv(quadricUv(s, Vec3(0, -1, z), part), 0.5f, 0);
    expectUv(quadricUv(s, Vec3(-0.5f, 0.5f, z), part), 0.25f, 0.75f);
  }
}

TEST(QuadricUv, ConeBodyAndCaps) {
  // height 2, radius 1 at the bottom, 0.5 at the top.
  Shape s = shapeOf(ShapeKind::Cone, 2, 1, 0.5f);
  // Body: v = z / height.
  expectUv(quadricUv(s, Vec3(1, 0, 0), 0), 0, 0);
  expectUv(quadricUv(s, Vec3(0, 0.75f, 1), 0), 0.25f, 0.5f);
  expectUv(quadricUv(s, Vec3(-0.5f, 0, 2), 0), 0.5f, 1);
  // Caps use their own radius: the rim maps to the edge of [0, 1]^2 on both.
  expectUv(quadricUv(s, Vec3(1, 0, 0), 1), 1, 0.5f);
  expectUv(quadricUv(s, Vec3(0.5f, 0, 2), 2), 1, 0.5f);
  expectUv(quadricUv(s, Vec3(0, -0.5f, 2), 2), 0.5f, 0);
  // A pointed cone (top radius 0) has no top cap; a zero radius must not divide by zero.
  Shape pointed = shapeOf(ShapeKind::Cone, 1, 1, 0);
  Vec2 uv = quadricUv(pointed, Vec3(0, 0, 1), 2);
  EXPECT_TRUE(std::isfinite(uv.x) && std::isfinite(uv.y));
}

// ---- through Scene::intersect, under transforms ------------------------------------------

std::unique_ptr<Scene> oneShape(ShapeKind kind, const Mat4& m, float height = 1, float r0 = 1,
                                float r1 = 0) {
  io::SceneDesc d;
  d.materials.emplace_back();
  d.objects.push_back(testing::primitive(kind, m, height, r0, r1));
  return Scene::build(d);
}

Hit shoot(const Scene& s, Vec3 o, Vec3 d) {
  Hit h;
  EXPECT_TRUE(s.intersect(Ray{o, normalize(d), 0, kInf}, h)) << o.x << "," << o.y << "," << o.z;
  return h;
}

constexpr double kQuarterTurn = 1.5707963267948966;

TEST(QuadricUvTransformed, SphereUvIsInTheLocalFrame) {
  // Local (0, 1, 0) (u = 0.25) -> scale 2 -> quarter turn about z -> (-2, 0, 0) -> (3, 0, 0).
  Mat4 m = Mat4::translate(5, 0, 0) * Mat4::rotate(0, 0, 1, kQuarterTurn) * Mat4::scale(2, 2, 2);
  auto s = oneShape(ShapeKind::Sphere, m);
  Hit h = shoot(*s, Vec3(-10, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(h.p.x, 3, 1e-4f);
  expectUv(h.uv, 0.25f, 0.5f, 1e-4f);
  // The local north pole is still the world +z pole (the rotation is about z).
  Hit top = shoot(*s, Vec3(5, 0, 10), Vec3(0, 0, -1));
  EXPECT_NEAR(top.uv.y, 1.0f, 1e-3f);
}

TEST(QuadricUvTransformed, BoxFaceUnderNonUniformScale) {
  // Box scaled (4, 2, 1) and moved up: the +z face spans x in [-2, 2], y in [-1, 1].
  auto s = oneShape(ShapeKind::Box, Mat4::translate(0, 0, 3) * Mat4::scale(4, 2, 1));
  Hit h = shoot(*s, Vec3(1, -0.5f, 10), Vec3(0, 0, -1));
  EXPECT_NEAR(h.p.z, 3.5f, 1e-4f);
  // Local (0.25, -0.25) on the +z face.
  expectUv(h.uv, 0.75f, 0.25f, 1e-4f);
  // The -x face: local (y, z) = (0.25, 0.1), u running along -y.
  Hit side = shoot(*s, Vec3(-10, 0.5f, 3.1f), Vec3(1, 0, 0));
  expectUv(side.uv, 0.25f, 0.6f, 1e-4f);
}

TEST(QuadricUvTransformed, SquareRotatedToFaceX) {
  // Rotated a quarter turn about y: local +x becomes world -z, local z (the normal) world +x.
  auto s = oneShape(ShapeKind::Square, Mat4::rotate(0, 1, 0, kQuarterTurn) * Mat4::scale(2, 2, 2));
  // World (0, 0.5, -0.5) is local (0.25, 0.25, 0).
  Hit h = shoot(*s, Vec3(5, 0.5f, -0.5f), Vec3(-1, 0, 0));
  expectUv(h.uv, 0.75f, 0.75f, 1e-4f);
}

TEST(QuadricUvTransformed, CylinderAndConeBodiesAndCaps) {
  // Cylinder stretched to height 4 and moved: v still runs 0..1 along it.
  auto cyl = oneShape(ShapeKind::Cylinder, Mat4::translate(0, 0, -2) * Mat4::scale(1, 1, 4));
  Hit body = shoot(*cyl, Vec3(0, 5, 1), Vec3(0, -1, 0));  // local (0, 1, 0.75)
  expectUv(body.uv, 0.25f, 0.75f, 1e-4f);
  Hit cap = shoot(*cyl, Vec3(0.5f, 0, 10), Vec3(0, 0, -1));  // top cap, local (0.5, 0)
  expectUv(cap.uv, 0.75f, 0.5f, 1e-4f);
  // Cone of height 2 (radius 1 -> 0.5) scaled by 3: the bottom cap seen from below.
  auto cone = oneShape(ShapeKind::Cone, Mat4::scale(3, 3, 3), 2, 1, 0.5f);
  Hit bottom = shoot(*cone, Vec3(0, -1.5f, -5), Vec3(0, 0, 1));  // local (0, -0.5, 0)
  expectUv(bottom.uv, 0.5f, 0.25f, 1e-4f);
  Hit side = shoot(*cone, Vec3(-10, 0, 3), Vec3(1, 0, 0));  // local z = 1: v = 0.5, u = 0.5
  expectUv(side.uv, 0.5f, 0.5f, 1e-4f);
}

// ---- textures through the scene ---------------------------------------------------------

// A square textured with a 2 x 2 image (top row red, green; bottom row blue, white),
// seen from +z: the texture must appear upright and unmirrored.
TEST(TexturedScene, SquareShowsTheImageUpright) {
  lc::testing::TempDir dir;
  io::Image img(2, 2);
  img.at(0, 0) = Color(1, 0, 0);
  img.at(1, 0) = Color(0, 1, 0);
  img.at(0, 1) = Color(0, 0, 1);
  img.at(1, 1) = Color(1, 1, 1);
  io::writeImage(dir.file("quad.png"), img);

  io::SceneDesc d;
  io::MaterialDesc m;
  m.diffuse.map = io::TextureRef{dir.file("quad.png"), SourceLoc{}, false};
  d.materials.push_back(m);
  io::ObjectDesc o;
  o.kind = ShapeKind::Square;
  d.objects.push_back(o);
  auto s = Scene::build(d);
  auto kdAt = [&](float x, float y) {
    return s->shadingMaterial(shoot(*s, Vec3(x, y, 5), Vec3(0, 0, -1))).kd;
  };
  // Texel centres: the quarter of the square nearest each corner.
  expectColor(kdAt(-0.25f, 0.25f), Color(1, 0, 0));   // top left
  expectColor(kdAt(0.25f, 0.25f), Color(0, 1, 0));    // top right
  expectColor(kdAt(-0.25f, -0.25f), Color(0, 0, 1));  // bottom left
  expectColor(kdAt(0.25f, -0.25f), Color(1, 1, 1));   // bottom right
}

// BuildOptions::linearizeSrgbTextures decodes sRGB-marked maps to linear values; without it
// (the default) every 8-bit map reads as value/255, and unmarked maps never change.
TEST(TexturedScene, SrgbMapsAreLinearisedOnlyWhenAsked) {
  lc::testing::TempDir dir;
  io::Image img(1, 1);
  img.at(0, 0) = Color(0.5f, 0.25f, 0.75f);
  io::writeImage(dir.file("grey.png"), img);
  const Color raw = io::readImage(dir.file("grey.png"), false).at(0, 0);
  const Color linear = io::readImage(dir.file("grey.png"), true).at(0, 0);
  ASSERT_NE(raw, linear);

  io::SceneDesc d;
  io::MaterialDesc marked, plain;
  marked.diffuse.map = io::TextureRef{dir.file("grey.png"), SourceLoc{}, true};
  plain.diffuse.map = io::TextureRef{dir.file("grey.png"), SourceLoc{}, false};
  d.materials = {marked, plain};
  io::ObjectDesc a, b;
  a.kind = b.kind = ShapeKind::Square;
  a.material = 0;
  b.material = 1;
  b.transform = Mat4::translate(3, 0, 0);
  d.objects = {a, b};

  for (bool linearize : {false, true}) {
    BuildOptions opt;
    opt.linearizeSrgbTextures = linearize;
    auto s = Scene::build(d, opt);
    Color markedKd = s->shadingMaterial(shoot(*s, Vec3(0, 0, 5), Vec3(0, 0, -1))).kd;
    Color plainKd = s->shadingMaterial(shoot(*s, Vec3(3, 0, 5), Vec3(0, 0, -1))).kd;
    SCOPED_TRACE(linearize ? "linearize" : "as value/255");
    expectColor(markedKd, linearize ? linear : raw, 1e-6f);
    expectColor(plainKd, raw, 1e-6f);
  }
}

}  // namespace
}  // namespace lc::scene
