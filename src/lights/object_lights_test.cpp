#include "lights/object_lights.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>
#include <string>

#include "io/image.h"
#include "io/ray_parser.h"
#include "test_util.h"

namespace lc::lights {
namespace {

using io::ShapeKind;
using scene::Scene;
using scene::Shape;

constexpr double kPiD = 3.14159265358979323846;

struct Built {
  std::unique_ptr<Scene> scene;
  std::vector<ObjectLightInfo> info;
  const HugeVector<Light>& lights() const { return scene->lights().lights; }
};

io::SceneDesc parse(const std::string& body, const std::string& baseDir = "/base") {
  return io::parseRayString("SBT-raytracer 1.0\n" + body, "t.ray", baseDir);
}

Built buildDesc(const io::SceneDesc& d, const ObjectLightOptions& o = {}) {
  Built b;
  b.scene = Scene::build(d);
  b.info = addObjectLights(*b.scene, o);
  return b;
}

Built build(const std::string& body, const ObjectLightOptions& o = {}) { return buildDesc(parse(body), o); }

// A luminous material block.
std::string lum(double intensity, double density, const std::string& colour = "(1, 1, 1)",
                const std::string& extra = "") {
  return "material = { diffuse = (0.5, 0.5, 0.5); luminosity = { colour = " + colour +
         "; intensity = " + std::to_string(intensity) + "; density = " + std::to_string(density) + "; " +
         extra + " }; };";
}

std::string tri(const std::string& mat, const std::string& pts, const std::string& extra = "") {
  return "trimesh { " + mat + " points = " + pts + "; faces = ((0, 1, 2)); " + extra + " }\n";
}

double sum(const HugeVector<Light>& ls, int c) {
  double s = 0;
  for (const Light& l : ls) s += l.intensity[c];
  return s;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// ---- counts ---------------------------------------------------------------------------

TEST(ObjectLights, ParseKindAndPlacement) {
  EXPECT_EQ(parseObjectLightKind("omni"), ObjectLightKind::Omni);
  EXPECT_EQ(parseObjectLightKind("oriented"), ObjectLightKind::Oriented);
  EXPECT_EQ(parsePlacement("seed"), Placement::Course);
  EXPECT_EQ(parsePlacement("stratified"), Placement::Stratified);
  EXPECT_THROW(parseObjectLightKind("spot"), Error);
  EXPECT_THROW(parsePlacement("random"), Error);
}

// Two triangles of areas 2 and 0.5: n_t = max(1, round(a_t * density)).
std::string twoTriangles(double density) {
  return "trimesh { name = panel; " + lum(10, density) +
         " points = ((0,0,0), (2,0,0), (0,2,0), (5,0,0), (6,0,0), (5,1,0));"
         " faces = ((0,1,2), (3,4,5)); }\n";
}

TEST(ObjectLights, MeshCountFormula) {
  struct Case {
    double density;
    uint64_t expected;
  } cases[] = {{1.3, 3 + 1}, {0, 1 + 1}, {10, 20 + 5}, {1.0, 2 + 1}, {3.0, 6 + 2} /* round(1.5) = 2 */};
  for (const Case& c : cases) {
    Built b = build(twoTriangles(c.density));
    ASSERT_EQ(b.info.size(), 1u);
    EXPECT_EQ(b.info[0].lights, c.expected) << "density " << c.density;
    EXPECT_EQ(b.lights().size(), c.expected);
    EXPECT_EQ(b.info[0].shape, 0);
    EXPECT_EQ(b.info[0].name, "panel");
    EXPECT_NEAR(b.info[0].area, 2.5, 1e-6);
  }
}

TEST(ObjectLights, ZeroAreaTrianglesGetNoLights) {
  Built b = build("trimesh { " + lum(1, 1) +
                  " points = ((0,0,0), (1,0,0), (0,1,0), (2,0,0)); faces = ((0,1,2), (0,1,3)); }\n");
  ASSERT_EQ(b.info.size(), 1u);
  EXPECT_EQ(b.info[0].lights, 1u);  // round(0.5) = 1 on the real triangle, none on the sliver
}

TEST(ObjectLights, QuadricCountFormula) {
  // Sphere of radius 2: area 16 pi = 50.27 -> 50 points.
  Built s = build("scale(2, sphere { " + lum(1, 1) + " })");
  EXPECT_EQ(s.info[0].lights, 50u);
  EXPECT_NEAR(s.info[0].area, 16 * kPiD, 1e-9 * 16 * kPiD);
  // Box 1 x 2 x 3: area 22 -> 44 points at density 2, one light each.
  Built bx = build("scale(1, 2, 3, box { " + lum(1, 2) + " })");
  EXPECT_EQ(bx.info[0].lights, 44u);
  EXPECT_NEAR(bx.info[0].area, 22, 1e-9);
  // Square 2 x 3: 9 points, two-sided: 18 lights.
  Built sq = build("scale(2, 3, 1, square { " + lum(1, 1.5) + " })");
  EXPECT_EQ(sq.info[0].lights, 18u);
  // Capped cylinder r = 1, h = 2: 4 pi + 2 pi = 18.85 -> 19 points; uncapped 4 pi -> 13 x 2.
  Built cy = build("scale(1, 1, 2, cylinder { " + lum(1, 1) + " })");
  EXPECT_EQ(cy.info[0].lights, 19u);
  Built oc = build("scale(1, 1, 2, cylinder { capped = false; " + lum(1, 1) + " })");
  EXPECT_EQ(oc.info[0].lights, 26u);
  // Density 0: still one point.
  Built z = build("sphere { " + lum(1, 0) + " }");
  EXPECT_EQ(z.info[0].lights, 1u);
  // Intensity 0: no lights at all.
  Built off = build("sphere { " + lum(0, 5) + " }");
  EXPECT_TRUE(off.info.empty());
  EXPECT_EQ(off.lights().size(), 0u);
}

TEST(ObjectLights, TotalPowerDoesNotDependOnDensity) {
  const std::string colour = "(0.9, 0.5, 0.25)";
  const std::string objects[] = {
      "trimesh { " + lum(37, 0) + " points = ((0,0,0), (2,0,0), (0,2,0), (5,0,0), (6,0,0), (5,1,0));"
                                  " faces = ((0,1,2), (3,4,5)); }",
      "scale(2, 1, 0.5, sphere { " + lum(37, 0, colour) + " })",
      "rotate(1, 1, 0, 0.3, scale(2, 3, 1, square { " + lum(37, 0, colour) + " }))",
      "scale(1, 2, 1, cone { capped = true; top_radius = 0.3; " + lum(37, 0, colour) + " })",
  };
  for (const std::string& obj : objects) {
    std::vector<double> totals;
    for (double density : {0.0, 0.7, 3.0, 41.0, 400.0}) {
      std::string text = obj;
      size_t at = text.find("density = ");
      text.replace(at, text.find(';', at) - at, "density = " + std::to_string(density));
      Built b = build(text);
      ASSERT_EQ(b.info.size(), 1u);
      double g = sum(b.lights(), 1);
      totals.push_back(g);
      EXPECT_NEAR(b.info[0].power.y, g, 1e-6 * g);
    }
    double expectG = obj.find(colour) != std::string::npos ? 37 * 0.5 : 37;
    for (double t : totals) EXPECT_NEAR(t, expectG, 1e-6 * expectG) << obj;
    for (double t : totals) EXPECT_LT(std::fabs(t - totals[0]) / totals[0], 1e-6) << obj;
  }
}

// ---- on the surface, with the right normal ----------------------------------------------

// Closest point of a quadric's part `part` to local point q (local coordinates).
Vec3 closestOnPart(const Shape& s, const Vec3& q, int part) {
  auto cl = [](float v, float lo, float hi) { return std::clamp(v, lo, hi); };
  switch (s.kind) {
    case ShapeKind::Sphere: return normalize(q);
    case ShapeKind::Box: {
      Vec3 c(cl(q.x, -0.5f, 0.5f), cl(q.y, -0.5f, 0.5f), cl(q.z, -0.5f, 0.5f));
      c[part / 2] = (part % 2) ? 0.5f : -0.5f;
      return c;
    }
    case ShapeKind::Square: return Vec3(cl(q.x, -0.5f, 0.5f), cl(q.y, -0.5f, 0.5f), 0);
    case ShapeKind::Cylinder:
    case ShapeKind::Cone: {
      bool cyl = s.kind == ShapeKind::Cylinder;
      float h = cyl ? 1 : s.height, r0 = cyl ? 1 : s.bottomRadius, r1 = cyl ? 1 : s.topRadius;
      float rho = std::sqrt(q.x * q.x + q.y * q.y);
      float cx = rho > 0 ? q.x / rho : 1, cy = rho > 0 ? q.y / rho : 0;
      if (part == 0) {
        // Project (rho, z) on the segment (r0, 0)-(r1, h) of the half-plane.
        float ax = r0, az = 0, bx = r1 - r0, bz = h;
        float t = cl(((rho - ax) * bx + (q.z - az) * bz) / (bx * bx + bz * bz), 0, 1);
        float r = ax + t * bx;
        return Vec3(r * cx, r * cy, az + t * bz);
      }
      float r = part == 1 ? r0 : r1, rr = std::min(rho, r);
      return Vec3(rr * cx, rr * cy, part == 1 ? 0 : h);
    }
    case ShapeKind::Mesh: break;
  }
  return q;
}

int partCount(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::Box: return 6;
    case ShapeKind::Cylinder:
    case ShapeKind::Cone: return s.capped ? 3 : 1;
    default: return 1;
  }
}

// Every light is on the surface (< 1e-5 of the scene scale) facing along the outward normal
// (or, for two-sided emitters, in opposite pairs).
void expectOnSurface(const Built& b, bool twoSided) {
  const Scene& sc = *b.scene;
  const Shape& s = sc.shapes()[0];
  float scale = std::max(1.0f, maxComponent(vmax(vabs(sc.bounds().lo), vabs(sc.bounds().hi))));
  const auto& ls = b.lights();
  ASSERT_GT(ls.size(), 10u);
  std::map<int, int> perPart;
  for (size_t i = 0; i < ls.size(); ++i) {
    const Light& l = ls[i];
    Vec3 q = s.toLocal.point(l.position);
    // The part the light lies on; on an edge shared by two parts, the one it faces out of.
    float tol = 1e-5f * scale, bestDist = kInf, bestDot = -2;
    int bestPart = -1;
    for (int part = 0; part < partCount(s); ++part) {
      Vec3 c = closestOnPart(s, q, part);
      float d = length(s.toWorld.point(c) - l.position);
      bestDist = std::min(bestDist, d);
      if (!(d < tol)) continue;
      Vec3 n = normalize(s.toLocal.normalFromInverse(quadricLocalNormal(s, c, part)));
      float dn = twoSided ? std::fabs(dot(n, l.direction)) : dot(n, l.direction);
      if (dn > bestDot) bestDot = dn, bestPart = part;
    }
    ASSERT_LT(bestDist, tol) << "light " << i;
    ++perPart[bestPart];
    EXPECT_NEAR(length(l.direction), 1.0f, 1e-5f);
    EXPECT_GT(bestDot, 1 - 1e-5f) << "light " << i << " part " << bestPart;
    if (twoSided) {
      // Outward first, then inward, at the same point.
      const Light& other = ls[i ^ 1];
      EXPECT_EQ(other.position, l.position);
      EXPECT_EQ(other.direction, -l.direction);
      if (i % 2 == 0) {
        Vec3 c = closestOnPart(s, q, bestPart);
        Vec3 n = normalize(s.toLocal.normalFromInverse(quadricLocalNormal(s, c, bestPart)));
        EXPECT_GT(dot(n, l.direction), 0) << "light " << i;
      }
    }
  }
  EXPECT_EQ(int(perPart.size()), partCount(s)) << "every part (faces, caps, body) has lights";
}

// translate * rotate * shear * non-uniform scale, and a mirror (negative determinant).
const char* kTransforms[] = {
    "translate(1, 2, 3, rotate(1, 2, 0.5, 0.7, transform((1, 0.4, 0, 0), (0, 1, 0.3, 0), (0.2, 0, 1, 0), (0, 0, 0, 1), "
    "scale(2.0, 0.7, 1.3, @))))",
    "scale(-1.5, 0.8, 2.2, @)",
};

std::string place(const char* t, const std::string& obj) {
  std::string s = t;
  s.replace(s.find('@'), 1, obj);
  return s;
}

TEST(ObjectLights, QuadricLightsLieOnTheSurfaceWithOutwardNormals) {
  struct Case {
    std::string obj;
    bool twoSided;
  } cases[] = {
      {"sphere { " + lum(1, 40) + " }", false},
      {"box { " + lum(1, 60) + " }", false},
      {"square { " + lum(1, 150) + " }", true},
      {"cylinder { " + lum(1, 40) + " }", false},
      {"cylinder { capped = false; " + lum(1, 40) + " }", true},
      {"cone { height = 1.5; bottom_radius = 1; top_radius = 0.4; " + lum(1, 40) + " }", false},
      {"cone { height = 1.5; bottom_radius = 0.2; top_radius = 1.0; capped = false; " + lum(1, 40) + " }", true},
  };
  for (const char* t : kTransforms)
    for (const Case& c : cases) {
      SCOPED_TRACE(place(t, c.obj));
      Built b = build(place(t, c.obj));
      expectOnSurface(b, c.twoSided);
    }
}

TEST(ObjectLights, MeshLightsLieOnTheirTrianglesFacingTheWindingNormal) {
  Built b = build("rotate(1, 0, 0, 0.4, scale(3, 1, 2, trimesh { " + lum(1, 30) +
                  " points = ((0,0,0), (1,0,0), (1,1,0.5), (0,1,0)); faces = ((0,1,2), (0,2,3)); }))");
  const scene::Mesh& m = b.scene->meshes()[0];
  ASSERT_GT(b.lights().size(), 50u);
  for (const Light& l : b.lights()) {
    bool found = false;
    for (const auto& t : m.triangles) {
      Vec3 p0 = m.positions[size_t(t[0])], p1 = m.positions[size_t(t[1])], p2 = m.positions[size_t(t[2])];
      Vec3 n = normalize(cross(p1 - p0, p2 - p0));
      if (std::fabs(dot(l.position - p0, n)) > 1e-5f) continue;
      // Inside: barycentrics from areas.
      float a = length(cross(p1 - p0, p2 - p0));
      float b0 = dot(cross(p1 - l.position, p2 - l.position), n) / a;
      float b1 = dot(cross(p2 - l.position, p0 - l.position), n) / a;
      if (b0 < -1e-5f || b1 < -1e-5f || b0 + b1 > 1 + 1e-5f) continue;
      found = true;
      EXPECT_GT(dot(l.direction, n), 1 - 1e-6f);
      EXPECT_EQ(l.type, LightType::Oriented);
    }
    EXPECT_TRUE(found) << l.position.x << " " << l.position.y << " " << l.position.z;
  }
}

TEST(ObjectLights, TwoSidedEmittersGiveOppositePairsWithHalfTheIntensity) {
  Built b = build("rotate(0, 1, 0, 0.5, scale(2, 1, 1, square { " + lum(8, 10, "(1, 0.5, 0.25)") + " }))");
  const auto& ls = b.lights();
  ASSERT_EQ(ls.size(), 2u * 20u);  // 20 points
  for (size_t i = 0; i < ls.size(); i += 2) {
    EXPECT_EQ(ls[i].position, ls[i + 1].position);
    EXPECT_EQ(ls[i].direction, -ls[i + 1].direction);
    EXPECT_EQ(ls[i].intensity, ls[i + 1].intensity);
    EXPECT_NEAR(ls[i].intensity.x, 8.0 / 20 / 2, 1e-6);
    EXPECT_NEAR(ls[i].intensity.y, 8.0 * 0.5 / 20 / 2, 1e-6);
  }
  EXPECT_NEAR(sum(ls, 0), 8, 1e-5);

  // area_light: a two-sided mesh.
  Built a = build("area_light { position = (0, 2, 0); u = (1, 0, 0); v = (0, 0, 2); colour = (1, 1, 1); }");
  EXPECT_TRUE(a.scene->shapes()[0].twoSidedEmission);
  ASSERT_EQ(a.info.size(), 1u);
  EXPECT_EQ(a.info[0].lights, 4u);  // two triangles of area 1 at density 1, two lights each
  for (size_t i = 0; i < a.lights().size(); i += 2) {
    EXPECT_EQ(a.lights()[i].direction, -a.lights()[i + 1].direction);
    EXPECT_NEAR(std::fabs(a.lights()[i].direction.y), 1, 1e-6);
  }

  // A plain mesh emits along its winding normal only.
  Built m = build(tri(lum(1, 1), "((0,0,0), (2,0,0), (0,2,0))"));
  EXPECT_EQ(m.lights().size(), 2u);
  for (const Light& l : m.lights()) EXPECT_EQ(l.direction, Vec3(0, 0, 1));
}

TEST(ObjectLights, OmniKindGivesOneOmniLightPerPoint) {
  ObjectLightOptions o;
  o.kind = ObjectLightKind::Omni;
  Built b = build("scale(2, 1, 1, square { " + lum(4, 10) + " })", o);
  ASSERT_EQ(b.lights().size(), 20u);  // no pairs for omni lights
  for (const Light& l : b.lights()) {
    EXPECT_EQ(l.type, LightType::Omni);
    EXPECT_NEAR(l.intensity.x, 4.0 / 20, 1e-6);
  }
  Built s = build("sphere { " + lum(3, 2) + " }", o);
  EXPECT_EQ(s.lights().size(), 25u);  // round(4 pi * 2)
  for (const Light& l : s.lights()) EXPECT_EQ(l.type, LightType::Omni);
}

TEST(ObjectLights, LightsOfALuminosityShareOneGroupWithItsAttenuation) {
  Built b = build("point_light { position = (0, 5, 0); colour = (1, 1, 1); }\n"
                  "sphere { " + lum(1, 1, "(1,1,1)", "constant_attenuation_coeff = 0.5; linear_attenuation_coeff = 0.25; quadratic_attenuation_coeff = 0.125;") + " }\n"
                  "translate(3, 0, 0, sphere { " + lum(1, 1) + " })\n");
  const LightSet& set = b.scene->lights();
  ASSERT_EQ(set.lights.size(), 1u + 13u + 13u);
  uint16_t g1 = set.lights[1].group, g2 = set.lights[14].group;
  for (size_t i = 1; i < 14; ++i) EXPECT_EQ(set.lights[i].group, g1);
  for (size_t i = 14; i < 27; ++i) EXPECT_EQ(set.lights[i].group, g2);
  EXPECT_NE(g1, g2);
  EXPECT_EQ(set.groups[g1].atten, (Attenuation{0.5f, 0.25f, 0.125f, kInf}));
  EXPECT_EQ(g2, set.lights[0].group);  // default attenuation: shared with the point light
}

// ---- textures -----------------------------------------------------------------------------

// A 2x2 checker: texel (0,0) (bottom-left) and (1,1) red, the others blue.
std::string writeChecker(const testing::TempDir& dir) {
  io::Image img(2, 2);
  img.at(0, 1) = Color(1, 0, 0);  // bottom-left (rows are stored top first)
  img.at(1, 0) = Color(1, 0, 0);  // top-right
  img.at(1, 1) = Color(0, 0, 1);
  img.at(0, 0) = Color(0, 0, 1);
  std::string path = dir.file("checker.bmp");
  io::writeImage(path, img);
  return path;
}

TEST(ObjectLights, TextureColoursAtKnownBarycentricPoints) {
  testing::TempDir dir;
  std::string tex = writeChecker(dir);
  // uvs chosen so that the seed pattern's points C + (V_j - C)/2 land on texel centres:
  // uv(S_j) = (uv_j + C_uv) / 2 with C_uv = (5/12, 5/12).
  auto scene = [&](double density, const std::string& colourWord) {
    return "trimesh { material = { diffuse = map(\"" + tex + "\"); luminosity = { colour = " + colourWord +
           "; intensity = 12; density = " + std::to_string(density) +
           "; }; }; points = ((0,0,0), (2,0,0), (0,2,0)); texture_uv = ((0.0833333333, 0.0833333333), "
           "(1.0833333333, 0.0833333333), (0.0833333333, 1.0833333333)); faces = ((0, 1, 2)); }\n";
  };
  ObjectLightOptions seed;
  seed.placement = Placement::Course;
  for (const std::string& colourWord : {std::string("map(\"") + tex + "\")", std::string("texture")}) {
    Built b = buildDesc(io::parseRayString("SBT-raytracer 1.0\n" + scene(2, colourWord), "t.ray", dir.path()), seed);
    const auto& ls = b.lights();
    ASSERT_EQ(ls.size(), 4u);  // area 2 * density 2
    const double q = 12.0 / 4;
    // Centroid: uv (5/12, 5/12) = 1/3 of a texel from texel (0,0)'s centre in u and v:
    // 4/9 red (0,0) + 1/9 red (1,1) + 4/9 blue.
    EXPECT_NEAR(ls[0].intensity.x, q * 5 / 9, 1e-4);
    EXPECT_NEAR(ls[0].intensity.z, q * 4 / 9, 1e-4);
    EXPECT_NEAR(ls[0].intensity.y, 0, 1e-6);
    // The spokes: red at S_0, blue at S_1 and S_2.
    EXPECT_NEAR(ls[1].intensity.x, q, 1e-4);
    EXPECT_NEAR(ls[1].intensity.z, 0, 1e-4);
    EXPECT_NEAR(ls[2].intensity.x, 0, 1e-4);
    EXPECT_NEAR(ls[2].intensity.z, q, 1e-4);
    EXPECT_NEAR(ls[3].intensity.x, 0, 1e-4);
    EXPECT_NEAR(ls[3].intensity.z, q, 1e-4);
  }
  // Stratified with one light: the centroid's colour.
  Built one = buildDesc(io::parseRayString("SBT-raytracer 1.0\n" + scene(0, "texture"), "t.ray", dir.path()));
  ASSERT_EQ(one.lights().size(), 1u);
  EXPECT_NEAR(one.lights()[0].intensity.x, 12.0 * 5 / 9, 1e-4);
  EXPECT_NEAR(one.lights()[0].intensity.z, 12.0 * 4 / 9, 1e-4);
}

TEST(ObjectLights, QuadricTextureColourFollowsQuadricUv) {
  testing::TempDir dir;
  std::string tex = writeChecker(dir);
  // A square's uv is (x + 1/2, y + 1/2): the quadrant x < 0, y < 0 is texel (0,0) = red.
  ObjectLightOptions o;
  o.kind = ObjectLightKind::Omni;
  Built b = buildDesc(io::parseRayString("SBT-raytracer 1.0\nsquare { material = { luminosity = { colour = map(\"" +
                                             tex + "\"); intensity = 1024; density = 1024; }; }; }\n",
                                         "t.ray", dir.path()),
                      o);
  ASSERT_EQ(b.lights().size(), 1024u);
  int checked = 0;
  for (const Light& l : b.lights()) {
    Vec2 uv = quadricUv(b.scene->shapes()[0], l.position, 0);
    // Within 1/32 of a texel centre the bilinear lookup is at least 88% that texel.
    float cu = uv.x < 0.5f ? 0.25f : 0.75f, cv = uv.y < 0.5f ? 0.25f : 0.75f;
    if (std::fabs(uv.x - cu) > 1.0f / 32 || std::fabs(uv.y - cv) > 1.0f / 32) continue;
    bool red = (uv.x < 0.5f) == (uv.y < 0.5f);
    EXPECT_GT(red ? l.intensity.x : l.intensity.z, 0.87f);
    EXPECT_LT(red ? l.intensity.z : l.intensity.x, 0.13f);
    ++checked;
  }
  EXPECT_GE(checked, 8);
  // Every light's colour is the texture at its uv.
  auto texture = scene::Texture::load(tex, false, Limits{});
  for (const Light& l : b.lights()) {
    Color c = texture->lookup(quadricUv(b.scene->shapes()[0], l.position, 0));
    EXPECT_NEAR(l.intensity.x, c.x, 1e-5);
    EXPECT_NEAR(l.intensity.z, c.z, 1e-5);
  }
}

// ---- placement patterns -------------------------------------------------------------------

// The lights of one triangle (0,0,0), (3,0,0), (0,3,0) (area 4.5) with n points.
std::vector<Vec3> trianglePoints(uint64_t n, Placement p) {
  ObjectLightOptions o;
  o.placement = p;
  Built b = build(tri(lum(1, double(n) / 4.5), "((0,0,0), (3,0,0), (0,3,0))"), o);
  std::vector<Vec3> out;
  for (const Light& l : b.lights()) out.push_back(l.position);
  return out;
}

void expectPoint(const Vec3& got, const Vec3& want) {
  EXPECT_NEAR(got.x, want.x, 1e-5);
  EXPECT_NEAR(got.y, want.y, 1e-5);
  EXPECT_NEAR(got.z, want.z, 1e-5);
}

TEST(ObjectLights, SeedPatternForSmallBudgets) {
  const Vec3 v[3] = {Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 3, 0)};
  const Vec3 c(1, 1, 0);
  auto spoke = [&](int j, double t) { return c + (v[j] - c) * float(t); };

  auto p1 = trianglePoints(1, Placement::Course);
  ASSERT_EQ(p1.size(), 1u);
  expectPoint(p1[0], c);

  // n = 4: the centroid and the midpoints of the centroid-vertex lines.
  auto p4 = trianglePoints(4, Placement::Course);
  ASSERT_EQ(p4.size(), 4u);
  expectPoint(p4[0], c);
  for (int j = 0; j < 3; ++j) expectPoint(p4[size_t(j + 1)], spoke(j, 0.5));

  // n = 2, 3: the spokes in vertex order, stopping mid-round.
  auto p2 = trianglePoints(2, Placement::Course);
  ASSERT_EQ(p2.size(), 2u);
  expectPoint(p2[1], spoke(0, 0.5));

  // n = 7: then the midpoints between those lights, edges (0,1), (1,2), (2,0).
  auto p7 = trianglePoints(7, Placement::Course);
  ASSERT_EQ(p7.size(), 7u);
  for (int e = 0; e < 3; ++e) expectPoint(p7[size_t(4 + e)], (spoke(e, 0.5) + spoke((e + 1) % 3, 0.5)) * 0.5f);

  // n = 13: k = round(sqrt(12/3)) = 2 levels at 1/3 and 2/3, then the outer level's
  // edge midpoints before the inner one's.
  auto p13 = trianglePoints(13, Placement::Course);
  ASSERT_EQ(p13.size(), 13u);
  for (int l = 1; l <= 2; ++l)
    for (int j = 0; j < 3; ++j) expectPoint(p13[size_t(1 + 3 * (l - 1) + j)], spoke(j, l / 3.0));
  for (int e = 0; e < 3; ++e) {
    expectPoint(p13[size_t(7 + e)], (spoke(e, 2 / 3.0) + spoke((e + 1) % 3, 2 / 3.0)) * 0.5f);
    expectPoint(p13[size_t(10 + e)], (spoke(e, 1 / 3.0) + spoke((e + 1) % 3, 1 / 3.0)) * 0.5f);
  }

  // Large budgets: all distinct, all inside.
  auto big = trianglePoints(500, Placement::Course);
  ASSERT_EQ(big.size(), 500u);
  std::set<std::tuple<float, float>> unique;
  for (const Vec3& p : big) {
    EXPECT_GE(p.x, -1e-6f);
    EXPECT_GE(p.y, -1e-6f);
    EXPECT_LE(p.x + p.y, 3 + 1e-5f);
    unique.insert({p.x, p.y});
  }
  EXPECT_EQ(unique.size(), 500u);
}

TEST(ObjectLights, StratifiedPlacementIsAreaUniformAndStartsAtTheCentroid) {
  auto p1 = trianglePoints(1, Placement::Stratified);
  ASSERT_EQ(p1.size(), 1u);
  expectPoint(p1[0], Vec3(1, 1, 0));

  // The four sub-triangles cut by the edge midpoints each get a quarter (+- 2%).
  const uint64_t n = 4000;
  auto ps = trianglePoints(n, Placement::Stratified);
  ASSERT_EQ(ps.size(), n);
  int counts[4] = {0, 0, 0, 0};
  for (const Vec3& p : ps) {
    ASSERT_GE(p.x, -1e-6f);
    ASSERT_GE(p.y, -1e-6f);
    ASSERT_LE(p.x + p.y, 3 + 1e-5f);
    int k = p.x > 1.5f ? 1 : p.y > 1.5f ? 2 : (p.x + p.y < 1.5f ? 0 : 3);
    ++counts[k];
  }
  for (int c : counts) EXPECT_NEAR(c, n / 4.0, 0.02 * n / 4.0);
  // Finer: a 10x10 grid over the square, cells fully inside the triangle hold n * 0.09 / 4.5.
  std::map<std::pair<int, int>, int> cells;
  for (const Vec3& p : ps) ++cells[{int(p.x / 0.3f), int(p.y / 0.3f)}];
  for (int i = 0; i < 10; ++i)
    for (int j = 0; i + j + 2 <= 10; ++j) EXPECT_NEAR(cells[std::make_pair(i, j)], n * 0.09 / 4.5, 15) << i << " " << j;
}

// ---- errors ------------------------------------------------------------------------------

io::SceneDesc descWithLuminosity(const std::function<void(io::LuminosityDesc&)>& edit) {
  io::SceneDesc d;
  d.materials.emplace_back();
  io::MaterialDesc m;
  io::LuminosityDesc l;
  l.loc = SourceLoc{"x.ray", 7, 13};
  edit(l);
  m.luminosity = l;
  d.materials.push_back(m);
  io::ObjectDesc o;
  o.kind = ShapeKind::Sphere;
  o.material = 1;
  d.objects.push_back(o);
  io::LightDesc pl;
  d.lights.push_back(pl);
  return d;
}

TEST(ObjectLights, BadValuesAreErrorsAtTheLuminosityAndAllocateNothing) {
  struct Case {
    std::function<void(io::LuminosityDesc&)> edit;
    const char* word;
  } cases[] = {
      {[](io::LuminosityDesc& l) { l.density = -1; }, "density"},
      {[](io::LuminosityDesc& l) { l.density = std::numeric_limits<float>::infinity(); }, "density"},
      {[](io::LuminosityDesc& l) { l.intensity = std::nanf(""); }, "intensity"},
      {[](io::LuminosityDesc& l) { l.intensity = -2; }, "intensity"},
      {[](io::LuminosityDesc& l) { l.attenLinear = -0.5f; }, "linear_attenuation_coeff"},
      {[](io::LuminosityDesc& l) { l.attenQuadratic = std::nanf(""); }, "quadratic_attenuation_coeff"},
      {[](io::LuminosityDesc& l) { l.colour.value = Color(1, -1, 0); }, "colour"},
  };
  for (const Case& c : cases) {
    auto scene = Scene::build(descWithLuminosity(c.edit));
    size_t before = scene->lights().lights.size(), cap = scene->lights().lights.capacity();
    std::string msg = errorOf([&] { addObjectLights(*scene, {}); });
    EXPECT_EQ(msg.rfind("x.ray:7:13: error: luminosity ", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.word), std::string::npos) << msg;
    EXPECT_EQ(scene->lights().lights.size(), before);
    EXPECT_EQ(scene->lights().lights.capacity(), cap);
  }
}

TEST(ObjectLights, TooManyLightsIsAnErrorNamingTheCountAndTheFlag) {
  // Line 4, column 23: the luminosity of the second sphere, which goes over the limit.
  io::SceneDesc d = parse("point_light { position = (0, 5, 0); }\n"
                          "sphere { material = { luminosity = { density = 10; }; }; }\n"
                          "sphere { material = { luminosity = { density = 1e4; }; }; }\n");
  auto scene = Scene::build(d);
  ObjectLightOptions o;
  o.maxLights = 1000;
  size_t cap = scene->lights().lights.capacity();
  std::string msg = errorOf([&] { addObjectLights(*scene, o); });
  // 4 pi * 10 = 126 and 4 pi * 1e4 = 125664 lights.
  EXPECT_EQ(msg, "t.ray:4:23: error: luminous objects need 125790 lights (125791 with the scene's other "
                 "lights), more than --max-lights (1000)");
  EXPECT_EQ(scene->lights().lights.size(), 1u);
  EXPECT_EQ(scene->lights().lights.capacity(), cap);
  // Exactly at the limit is fine.
  o.maxLights = 1 + 126 + 125664;
  EXPECT_EQ(addObjectLights(*scene, o).size(), 2u);
  EXPECT_EQ(scene->lights().size(), o.maxLights);

  // An absurd density cannot overflow the count.
  io::SceneDesc huge = parse("scale(1e15, sphere { material = { luminosity = { density = 1e30; }; }; })\n");
  auto hs = Scene::build(huge);
  std::string hm = errorOf([&] { addObjectLights(*hs, {}); });
  EXPECT_NE(hm.find("t.ray:2:"), std::string::npos) << hm;
  EXPECT_NE(hm.find("more than --max-lights (20000000)"), std::string::npos) << hm;
}

// ---- quadric areas and area-uniform sampling ---------------------------------------------

double luminousArea(const std::string& obj) {
  Built b = build(obj);
  return b.info.at(0).area;
}

TEST(ObjectLights, WorldAreaOfTransformedQuadrics) {
  // Oblate spheroid a = 2, c = 1 and prolate a = 1, c = 3 (closed forms), rotated.
  {
    double a = 2, c = 1, e = std::sqrt(1 - c * c / (a * a));
    double want = 2 * kPiD * a * a + kPiD * c * c / e * std::log((1 + e) / (1 - e));
    EXPECT_NEAR(luminousArea("rotate(1, 2, 3, 0.9, scale(2, 2, 1, sphere { " + lum(1, 0) + " }))"), want, 1e-9 * want);
  }
  for (double c : {3.0, 30.0, 100.0}) {
    double a = 1, e = std::sqrt(1 - a * a / (c * c));
    double want = 2 * kPiD * a * a * (1 + c / (a * e) * std::asin(e));
    EXPECT_NEAR(luminousArea("rotate(1, 0, 1, 0.4, scale(1, 1, " + std::to_string(c) + ", sphere { " + lum(1, 0) + " }))"),
                want, 1e-9 * want)
        << c;
  }
  // A sheared box: the sum of its parallelogram faces.
  {
    Mat4 m = Mat4::identity();
    m.m[0][1] = 0.5;
    m.m[1][2] = -0.3;
    m = m * Mat4::scale(1, 2, 3);
    double want = 0;
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 e1(0, 0, 0), e2(0, 0, 0);
      e1[(axis + 1) % 3] = 1;
      e2[(axis + 2) % 3] = 1;
      want += 2 * length(cross(m.vector(e1), m.vector(e2)));
    }
    EXPECT_NEAR(luminousArea("transform((1, 0.5, 0, 0), (0, 1, -0.3, 0), (0, 0, 1, 0), (0, 0, 0, 1), scale(1, 2, 3, box { " +
                             lum(1, 0) + " }))"),
                want, 1e-6 * want);
  }
  // Elliptic cylinder (semi-axes 2, 1; height 3) with caps: the perimeter by a fine polygon.
  {
    double per = 0;
    const int n = 1 << 20;
    for (int i = 0; i < n; ++i) {
      double t0 = 2 * kPiD * i / n, t1 = 2 * kPiD * (i + 1) / n;
      per += std::hypot(2 * (std::cos(t1) - std::cos(t0)), std::sin(t1) - std::sin(t0));
    }
    double want = per * 3 + 2 * kPiD * 2;
    EXPECT_NEAR(luminousArea("scale(2, 1, 3, cylinder { " + lum(1, 0) + " })"), want, 1e-9 * want);
  }
  // Cone frustum under a uniform scale of 2: lateral pi (r0 + r1) slant + both caps.
  {
    double r0 = 1, r1 = 0.5, h = 2, slant = std::hypot(h, r0 - r1);
    double want = 4 * (kPiD * (r0 + r1) * slant + kPiD * (r0 * r0 + r1 * r1));
    EXPECT_NEAR(luminousArea("scale(2, cone { height = 2; bottom_radius = 1; top_radius = 0.5; " + lum(1, 0) + " })"),
                want, 1e-9 * want);
  }
}

TEST(ObjectLights, LightsAreUniformByWorldAreaOnAScaledSphere) {
  // A rotated ellipsoid with semi-axes 1, 0.6, 4 (along local z). Uniform sampling of the
  // unit sphere would put 1/8 of the lights in each of 8 equal-height bands of local z
  // (Archimedes); by world area the middle bands hold far more than the polar ones.
  Mat4 m = Mat4::rotate(1, 1, 0, 0.6) * Mat4::scale(1, 0.6, 4);
  Built b = build("rotate(1, 1, 0, 0.6, scale(1, 0.6, 4, sphere { " + lum(1, 700) + " }))");
  const auto& ls = b.lights();
  ASSERT_GT(ls.size(), 15000u);
  const Shape& s = b.scene->shapes()[0];

  // World band areas from an independent fine tessellation of the transformed sphere.
  const int bands = 8, rowsPerBand = 64, cols = 1024;
  std::vector<double> area(bands, 0);
  auto vertex = [&](double z, double phi) {
    double r = std::sqrt(std::max(0.0, 1 - z * z));
    return m.point(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
  };
  for (int band = 0; band < bands; ++band)
    for (int row = 0; row < rowsPerBand; ++row) {
      double z0 = -1 + 2.0 * (band * rowsPerBand + row) / (bands * rowsPerBand);
      double z1 = -1 + 2.0 * (band * rowsPerBand + row + 1) / (bands * rowsPerBand);
      for (int c = 0; c < cols; ++c) {
        double f0 = 2 * kPiD * c / cols, f1 = 2 * kPiD * (c + 1) / cols;
        Vec3 a = vertex(z0, f0), bb = vertex(z0, f1), cc = vertex(z1, f1), d = vertex(z1, f0);
        area[size_t(band)] += 0.5 * length(cross(bb - a, cc - a)) + 0.5 * length(cross(cc - a, d - a));
      }
    }
  double total = 0;
  for (double a : area) total += a;
  EXPECT_NEAR(total, b.info[0].area, 2e-4 * total);

  std::vector<double> count(bands, 0);
  for (const Light& l : ls) {
    double z = s.toLocal.point(l.position).z;
    int band = std::clamp(int((z + 1) / 2 * bands), 0, bands - 1);
    count[size_t(band)] += 1;
  }
  double maxDev = 0;
  for (int band = 0; band < bands; ++band) {
    double want = area[size_t(band)] / total, got = count[size_t(band)] / double(ls.size());
    EXPECT_NEAR(got, want, 0.003) << "band " << band;
    maxDev = std::max(maxDev, std::fabs(want - 0.125));
  }
  EXPECT_GT(maxDev, 0.03) << "the test must tell world-uniform from local-uniform";
  // Two regions of equal world area by symmetry (the two halves z > 0 and z < 0) hold equal
  // counts, and the polar band holds its (much smaller) share.
  double upper = 0;
  for (int band = 4; band < 8; ++band) upper += count[size_t(band)];
  EXPECT_NEAR(upper / double(ls.size()), 0.5, 0.002);
}

// ---- determinism, the surface look, and an end-to-end render ------------------------------

TEST(ObjectLights, SameLightsAtAnyThreadCount) {
  const std::string text = "trimesh { " + lum(5, 50) +
                           " points = ((0,0,0), (4,0,0), (4,4,1), (0,4,0), (2, 2, 3)); faces = ((0,1,2), (0,2,3), "
                           "(0, 1, 4), (1, 2, 4), (2, 3, 4)); }\n"
                           "scale(2, 1, 1, sphere { " + lum(5, 50) + " })\n";
  HugeVector<Light> one, many;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = build(text).lights();
  }
  many = build(text).lights();
  ASSERT_EQ(one.size(), many.size());
  ASSERT_GT(one.size(), 1000u);
  for (size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(one[i].position, many[i].position) << i;
    ASSERT_EQ(one[i].direction, many[i].direction) << i;
    ASSERT_EQ(one[i].intensity, many[i].intensity) << i;
    ASSERT_EQ(one[i].type, many[i].type) << i;
    ASSERT_EQ(one[i].group, many[i].group) << i;
  }
}

TEST(ObjectLights, LuminousSurfaceLooksBright) {
  Built b = build("trimesh { " + lum(1, 1, "(0.2, 0.9, 0.3)") +
                  " points = ((-1,-1,0), (1,-1,0), (1,1,0), (-1,1,0)); faces = ((0,1,2), (0,2,3)); }\n"
                  "translate(5, 0, 0, sphere { material = { emissive = (0.1, 0.1, 0.1); luminosity = { colour = (1, 0, 0); }; }; })\n");
  scene::Hit h;
  ASSERT_TRUE(b.scene->intersect(scene::Ray{Vec3(0.3f, 0.2f, 5), Vec3(0, 0, -1)}, h));
  scene::ShadingMaterial sm = b.scene->shadingMaterial(h);
  EXPECT_NEAR(sm.ke.x, 0.2, 1e-6);
  EXPECT_NEAR(sm.ke.y, 0.9, 1e-6);
  EXPECT_NEAR(sm.ke.z, 0.3, 1e-6);
  // An explicit `emissive` wins.
  ASSERT_TRUE(b.scene->intersect(scene::Ray{Vec3(5, 0, 5), Vec3(0, 0, -1)}, h));
  sm = b.scene->shadingMaterial(h);
  EXPECT_NEAR(sm.ke.x, 0.1, 1e-6);
  EXPECT_NEAR(sm.ke.y, 0.1, 1e-6);
}

// The lightcuts binary: $LC_BINARY (set by ctest), else next to this test binary.
std::string lightcutsBinary() {
  if (const char* env = std::getenv("LC_BINARY")) return env;
  std::error_code ec;
  auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? "" : (self.parent_path() / "lightcuts").string();
}

// `emission = Le` (COMP4411) is a per-area luminosity: an area A at radiance Le gets total
// intensity A x Le / pi, on each side of a two-sided emitter; the camera sees Le.
TEST(ObjectLights, EmissionIsRadianceTimesArea) {
  Built b = build(
      // a 2 x 2 panel (object-level emission, as COMP4411's trimesh)
      "trimesh { material = { diffuse = (0.5, 0.5, 0.5); }; emission = (2, 1, 0.5);"
      " points = ((-1,-1,0), (1,-1,0), (1,1,0), (-1,1,0)); faces = ((0,1,2), (0,2,3)); }\n"
      // a sphere_light under scale 2: radius 2, area 16 pi
      "translate(10, 0, 0, scale(2, sphere_light { emission = (1, 2, 3); }))\n"
      // emission in a material, on a two-sided square of area 9 (scale 3)
      "translate(20, 0, 0, scale(3, square { material = { emission = (1, 1, 1); }; }))\n"
      // sphere_light radius
      "translate(30, 0, 0, sphere_light { emission = (1, 1, 1); radius = 0.5; })\n");
  ASSERT_EQ(b.info.size(), 4u);
  auto near = [](Color got, Color want, double rel) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], rel * std::max(1.0f, want[c])) << c;
  };
  const float ip = float(1 / kPiD);
  near(b.info[0].power, Color(8, 4, 2) * ip, 1e-5);
  EXPECT_NEAR(b.info[0].area, 4, 1e-6);
  near(b.info[1].power, Color(16, 32, 48), 1e-5);  // area 16 pi
  near(b.info[2].power, Color(18, 18, 18) * ip, 1e-5);  // 9 on each side
  near(b.info[3].power, Color(1, 1, 1), 1e-5);  // area pi
  // Density: --emission-density (ParseOptions::emissionDensity) lights per unit area.
  EXPECT_EQ(b.info[0].lights, 4u);
  io::ParseOptions po;
  po.emissionDensity = 25;
  Built dense = buildDesc(io::parseRayString(
      "SBT-raytracer 1.0\ntrimesh { emission = (2, 1, 0.5);"
      " points = ((-1,-1,0), (1,-1,0), (1,1,0), (-1,1,0)); faces = ((0,1,2), (0,2,3)); }\n",
      "t.ray", "/base", po));
  ASSERT_EQ(dense.info.size(), 1u);
  EXPECT_EQ(dense.info[0].lights, 100u);
  near(dense.info[0].power, Color(8, 4, 2) * ip, 1e-5);
  // The camera sees the emitters at Le.
  scene::Hit h;
  ASSERT_TRUE(b.scene->intersect(scene::Ray{Vec3(0.3f, 0.2f, 5), Vec3(0, 0, -1)}, h));
  near(b.scene->shadingMaterial(h).ke, Color(2, 1, 0.5f), 1e-6);
  ASSERT_TRUE(b.scene->intersect(scene::Ray{Vec3(10, 0, 5), Vec3(0, 0, -1)}, h));
  near(b.scene->shadingMaterial(h).ke, Color(1, 2, 3), 1e-6);
  EXPECT_NEAR(h.p.z, 2, 1e-3);
  // The panel keeps its own material's diffuse.
  ASSERT_TRUE(b.scene->intersect(scene::Ray{Vec3(0.3f, 0.2f, 5), Vec3(0, 0, -1)}, h));
  near(b.scene->shadingMaterial(h).kd, Color(0.5f, 0.5f, 0.5f), 1e-6);
}

// The centre pixel (through look_at) of a 33 x 33 brute-force render of `body` (a .ray
// scene after its header) by the CLI, at the given --emission-density.
Color brutePixelBelow(const std::string& body, int emissionDensity) {
  std::string bin = lightcutsBinary();
  EXPECT_TRUE(std::filesystem::exists(bin)) << "build the lightcuts target (" << bin << ")";
  testing::TempDir dir;
  std::string scene = dir.file("scene.ray"), out = dir.file("scene.exr");
  std::ofstream(scene) << "SBT-raytracer 1.0\n" << body;
  std::string cmd = "'" + bin + "' render '" + scene + "' -o '" + out + "' --width 33 --height 33 --method brute " +
                    "--emission-density " + std::to_string(emissionDensity) + " --threads 2 -q > '" +
                    dir.file("log.txt") + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  io::Image img = io::readImage(out);
  EXPECT_EQ(img.width, 33);
  return img.width == 33 ? img.at(16, 16) : Color(-1);
}

// Closed form: a square emitter of half-side a and radiance Le, facing down at height h over
// a diffuse plane (kd). The renderer's diffuse term is kd cos(theta_s) x I cos(theta_l) / d^2
// per oriented light (no 1/pi; point_light colour units), and the lights sum to A Le, so the
// plane below the centre shows kd Le times the integral of cos cos / d^2 over the square:
//   kd Le 4 X / sqrt(1 + X^2) atan(X / sqrt(1 + X^2)),   X = a / h   (-> kd Le A / h^2).
// Checked in process (every light) and through the CLI's brute-force render.
TEST(ObjectLights, EmittingSquareOverAPlaneMatchesTheClosedForm) {
  const double a = 0.5, hgt = 2, kd = 0.5, le = 3;
  const double X = a / hgt, r = std::sqrt(1 + X * X);
  // Irradiance E of a square of radiance Le, and the path tracer's kd / pi x E.
  const double want = kd / kPiD * le * 4 * X / r * std::atan(X / r);
  EXPECT_NEAR(want, kd / kPiD * le * 4 * a * a / (hgt * hgt), 0.1 * want);  // small-source limit (8% here)
  const std::string body =
      "camera { position = (0, -4, 1); look_at = (0, 0, 0); fov = 10; }\n"
      "trimesh { material = { diffuse = (0.5, 0.5, 0.5); };"
      " points = ((-10,-10,0), (10,-10,0), (10,10,0), (-10,10,0)); faces = ((0,1,2), (0,2,3)); }\n"
      "trimesh { emission = (3, 3, 3);"
      " points = ((-0.5,-0.5,2), (0.5,-0.5,2), (0.5,0.5,2), (-0.5,0.5,2)); faces = ((0,2,1), (0,3,2)); }\n";
  io::ParseOptions po;
  po.emissionDensity = 400;  // 400 lights on the unit square
  Built b = buildDesc(io::parseRayString("SBT-raytracer 1.0\n" + body, "t.ray", "/base", po));
  ASSERT_EQ(b.info.size(), 1u);
  EXPECT_EQ(b.info[0].lights, 400u);
  double sum = 0;
  const LightSet& set = b.scene->lights();
  for (const Light& l : set.lights) {
    Vec3 d = l.position;  // from the origin
    float dist = length(d);
    Vec3 wi = d / dist;
    sum += kd * l.intensity.y * set.groups[l.group].atten(dist) * std::max(0.0f, -dot(l.direction, wi)) *
           std::max(0.0f, wi.z);
  }
  EXPECT_NEAR(sum, want, 0.005 * want);

  const Color c = brutePixelBelow(body, 400);  // the plane right below the emitter
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], want, 0.01 * want) << k;
  std::printf("closed form %.5f, lights %.5f, brute render %.5f\n", want, sum, double(c.y));
}

// Closed form: a sphere of radius R and radiance Le, its centre at height H over a diffuse
// plane, lights the point below it with irradiance pi Le (R / H)^2, so the plane shows kd Le
// (R / H)^2 (the renderer's units, as above). A quarter of that comes from the lights seen
// at a slant (cos(theta_l) below 1/2): until December 2026 a shadow ray aimed at the light
// moved by the plane's normal offset, into the sphere, and many of those were hidden (the
// render came out 5.4% dark; 0.2% now).
TEST(ObjectLights, EmittingSphereOverAPlaneMatchesTheClosedForm) {
  const double R = 0.5, H = 2, kd = 0.5, le = 3;
  const double want = kd * le * (R / H) * (R / H);
  const std::string body =
      "camera { position = (0, -4, 1); look_at = (0, 0, 0); fov = 10; }\n"
      "trimesh { material = { diffuse = (0.5, 0.5, 0.5); };"
      " points = ((-10,-10,0), (10,-10,0), (10,10,0), (-10,10,0)); faces = ((0,1,2), (0,2,3)); }\n"
      "translate(0, 0, 2, sphere_light { emission = (3, 3, 3); radius = 0.5; })\n";
  const Color c = brutePixelBelow(body, 2000);  // the plane right below the emitter
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], want, 0.02 * want) << k;
  std::printf("closed form %.5f, brute render %.5f\n", want, double(c.y));
}

// The Cornell box lit by its ceiling panel: the floor below the panel is lit, and brighter
// than the floor's corners; in-process (every light, shadow rays) and through the renderer
// (the CLI, brute force at 64x64).
TEST(ObjectLights, CornellBoxFloorIsLitBelowThePanel) {
  auto sc = Scene::build(io::parseRayFile(testing::scenePath("cornell_box.ray")));
  auto info = addObjectLights(*sc, {});
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].lights, 256u);  // two triangles of 6825 mm^2 at 0.0188: 128 each
  EXPECT_NEAR(info[0].power.x, 300000, 1);
  const LightSet& set = sc->lights();
  auto irradiance = [&](Vec3 p, bool shadows) {
    double e = 0;
    for (const Light& l : set.lights) {
      Vec3 d = l.position - p;
      float dist = length(d);
      Vec3 wi = d / dist;
      float g = set.groups[l.group].atten(dist) * std::max(0.0f, -dot(l.direction, wi)) * std::max(0.0f, wi.y);
      if (g > 0 && !(shadows && sc->occluded(p + Vec3(0, 1e-2f, 0), wi, dist - 0.1f))) e += g * l.intensity.y;
    }
    return e;
  };
  // Straight below, without the boxes: about power / d^2 = 300000 * 0.85 / 548.7^2 = 0.847,
  // times the cosines (~0.985 on average over the panel).
  EXPECT_NEAR(irradiance(Vec3(278, 0, 279.5), false), 0.834, 0.005);
  // The boxes shade part of the floor below the panel; the best lit point there.
  double below = 0;
  for (float x = 158; x <= 398; x += 20)
    for (float z = 160; z <= 400; z += 20) below = std::max(below, irradiance(Vec3(x, 0, z), true));
  EXPECT_GT(below, 0.7);
  for (Vec3 corner : {Vec3(540, 0, 20), Vec3(20, 0, 20), Vec3(20, 0, 540), Vec3(540, 0, 540)})
    EXPECT_LT(irradiance(corner, true), 0.6 * below) << corner.x << " " << corner.z;

  // The renderer, through the CLI.
  std::string bin = lightcutsBinary();
  ASSERT_TRUE(std::filesystem::exists(bin)) << "build the lightcuts target (" << bin << ")";
  testing::TempDir dir;
  std::string out = dir.file("cornell.exr");
  std::string cmd = "'" + bin + "' render '" + testing::scenePath("cornell_box.ray") + "' -o '" + out +
                    "' --width 64 --height 64 --method brute --threads 2 -q > '" + dir.file("log.txt") + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  io::Image img = io::readImage(out);
  ASSERT_EQ(img.width, 64);
  ASSERT_EQ(img.height, 64);
  // Which pixels see the floor within 120 mm of the point below the panel's centre, and
  // which see it within 80 mm of its sides' ends (the corners).
  const scene::Camera& cam = sc->camera();
  double nearSum = 0, cornerSum = 0;
  int nearCount = 0, cornerCount = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      scene::Hit h;
      if (!sc->intersect(scene::Ray{cam.eye, cam.direction((x + 0.5f) / 64, (y + 0.5f) / 64)}, h)) continue;
      if (sc->shapes()[size_t(h.shape)].name != "floor") continue;
      float v = luminance(img.at(x, y));
      if (std::hypot(h.p.x - 278, h.p.z - 279.5f) < 120) nearSum += v, ++nearCount;
      if ((h.p.x < 80 || h.p.x > 476) && (h.p.z < 80 || h.p.z > 479)) cornerSum += v, ++cornerCount;
    }
  ASSERT_GT(nearCount, 5);
  ASSERT_GT(cornerCount, 5);
  double nearMean = nearSum / nearCount, cornerMean = cornerSum / cornerCount;
  EXPECT_GT(nearMean, 0.3);
  EXPECT_GT(nearMean, 1.5 * cornerMean);
  std::printf("floor below the panel %.3f, corners %.3f\n", nearMean, cornerMean);
}

}  // namespace
}  // namespace lc::lights

namespace lc::lights {
namespace {

// --seed shifts the stratified points (every kind of part): another seed places the lights
// elsewhere on the same surfaces with the same count and power; the same seed, the same
// lights; seed 1 is the default placement.
TEST(ObjectLights, SeedShiftsTheStratifiedPoints) {
  const std::string body =
      lum(10, 40) +
      "\ntrimesh { points = ((0,0,0), (1,0,0), (0,1,0)); faces = ((0,1,2)); }\n"
      "translate(3, 0, 0, box {})\n"
      "translate(6, 0, 0, cylinder {})\n"
      "translate(9, 0, 0, sphere {})\n";
  auto at = [&](uint64_t seed) {
    ObjectLightOptions o;
    o.seed = seed;
    return build(body, o);
  };
  Built def = build(body), one = at(1), a = at(7), again = at(7), b = at(8);
  ASSERT_EQ(def.lights().size(), a.lights().size());
  ASSERT_EQ(a.lights().size(), b.lights().size());
  ASSERT_GT(a.lights().size(), 100u);
  size_t moved = 0, movedB = 0;
  for (size_t i = 0; i < a.lights().size(); ++i) {
    EXPECT_EQ(one.lights()[i].position, def.lights()[i].position) << i;
    EXPECT_EQ(again.lights()[i].position, a.lights()[i].position) << i;
    moved += !(a.lights()[i].position == def.lights()[i].position);
    movedB += !(b.lights()[i].position == a.lights()[i].position);
  }
  EXPECT_GT(moved, a.lights().size() * 9 / 10);
  EXPECT_GT(movedB, a.lights().size() * 9 / 10);
  for (size_t k = 0; k < a.info.size(); ++k) {
    EXPECT_EQ(a.info[k].lights, def.info[k].lights);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.info[k].power[c], def.info[k].power[c], 1e-4 * def.info[k].power[c]);
  }
  // Still on the surfaces: the triangle's lights lie in it (z = 0, x, y >= 0, x + y <= 1).
  for (size_t i = 0; i < a.info[0].lights; ++i) {
    const Vec3& p = a.lights()[i].position;
    EXPECT_NEAR(p.z, 0, 1e-6);
    EXPECT_GE(p.x, -1e-6);
    EXPECT_GE(p.y, -1e-6);
    EXPECT_LE(p.x + p.y, 1 + 1e-5);
  }
}

}  // namespace
}  // namespace lc::lights
