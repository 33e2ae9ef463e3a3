#include "io/ray_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/file_util.h"
#include "io/ray_parser.h"
#include "test_util.h"

namespace lc::io {
namespace {

namespace fs = std::filesystem;

std::string absNorm(const std::string& p) { return fs::absolute(p).lexically_normal().string(); }

void expectSameTexture(const std::optional<TextureRef>& a, const std::optional<TextureRef>& b,
                       const std::string& what) {
  ASSERT_EQ(a.has_value(), b.has_value()) << what;
  if (a) {
    EXPECT_EQ(absNorm(a->path), absNorm(b->path)) << what;
  }
}

void expectSameColor(const ColorParam& a, const ColorParam& b, const std::string& what) {
  EXPECT_EQ(a.value, b.value) << what;
  expectSameTexture(a.map, b.map, what);
}

void expectSameScalar(const ScalarParam& a, const ScalarParam& b, const std::string& what) {
  EXPECT_EQ(a.value, b.value) << what;
  expectSameTexture(a.map, b.map, what);
}

void expectSameMaterial(const MaterialDesc& a, const MaterialDesc& b, const std::string& what) {
  EXPECT_EQ(a.name, b.name) << what;
  expectSameColor(a.emissive, b.emissive, what + " emissive");
  expectSameColor(a.ambient, b.ambient, what + " ambient");
  expectSameColor(a.diffuse, b.diffuse, what + " diffuse");
  expectSameColor(a.specular, b.specular, what + " specular");
  expectSameColor(a.reflective, b.reflective, what + " reflective");
  expectSameColor(a.transmissive, b.transmissive, what + " transmissive");
  expectSameScalar(a.shininess, b.shininess, what + " shininess");
  expectSameScalar(a.index, b.index, what + " index");
  EXPECT_EQ(a.emissiveSet, b.emissiveSet) << what;
  ASSERT_EQ(a.luminosity.has_value(), b.luminosity.has_value()) << what;
  if (a.luminosity) {
    const LuminosityDesc &x = *a.luminosity, &y = *b.luminosity;
    expectSameColor(x.colour, y.colour, what + " luminosity colour");
    EXPECT_EQ(x.colourFromDiffuse, y.colourFromDiffuse) << what;
    EXPECT_EQ(x.intensity, y.intensity) << what;
    EXPECT_EQ(x.perArea, y.perArea) << what;
    EXPECT_EQ(x.density, y.density) << what;
    EXPECT_EQ(x.attenConstant, y.attenConstant) << what;
    EXPECT_EQ(x.attenLinear, y.attenLinear) << what;
    EXPECT_EQ(x.attenQuadratic, y.attenQuadratic) << what;
  }
}

// Field-by-field equality of what a scene means (material indices may differ; the
// materials they point at may not).
void expectSameScene(const SceneDesc& a, const SceneDesc& b) {
  EXPECT_EQ(a.hasCamera, b.hasCamera);
  EXPECT_EQ(a.camera.position, b.camera.position);
  EXPECT_EQ(a.camera.viewDir, b.camera.viewDir);
  EXPECT_EQ(a.camera.upDir, b.camera.upDir);
  EXPECT_EQ(a.camera.fovDegrees, b.camera.fovDegrees);
  EXPECT_EQ(a.camera.aspectRatio, b.camera.aspectRatio);
  EXPECT_EQ(a.ambient, b.ambient);

  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    const LightDesc &x = a.lights[i], &y = b.lights[i];
    std::string w = "light " + std::to_string(i);
    EXPECT_EQ(x.kind, y.kind) << w;
    if (x.kind != LightKind::Directional) {
      EXPECT_EQ(x.position, y.position) << w;
    }
    if (x.kind != LightKind::Point) {
      EXPECT_EQ(x.direction, y.direction) << w;
    }
    EXPECT_EQ(x.colour, y.colour) << w;
    if (x.kind != LightKind::Directional) {
      EXPECT_EQ(x.attenConstant, y.attenConstant) << w;
      EXPECT_EQ(x.attenLinear, y.attenLinear) << w;
      EXPECT_EQ(x.attenQuadratic, y.attenQuadratic) << w;
    }
    if (x.kind == LightKind::Spot) {
      EXPECT_EQ(x.exponent, y.exponent) << w;
      EXPECT_EQ(x.cutoffDegrees, y.cutoffDegrees) << w;
      EXPECT_EQ(x.coneAngleDegrees, y.coneAngleDegrees) << w;
      EXPECT_EQ(x.penumbraDegrees, y.penumbraDegrees) << w;
      EXPECT_EQ(x.cutoffDistance, y.cutoffDistance) << w;
    }
  }

  ASSERT_EQ(a.instantRadiosity.has_value(), b.instantRadiosity.has_value());
  if (a.instantRadiosity) {
    EXPECT_EQ(a.instantRadiosity->vpls, b.instantRadiosity->vpls);
    EXPECT_EQ(a.instantRadiosity->bounces, b.instantRadiosity->bounces);
    EXPECT_EQ(a.instantRadiosity->normalize, b.instantRadiosity->normalize);
    EXPECT_EQ(a.instantRadiosity->clamp, b.instantRadiosity->clamp);
    EXPECT_EQ(a.instantRadiosity->seed, b.instantRadiosity->seed);
    EXPECT_EQ(a.instantRadiosity->caustics, b.instantRadiosity->caustics);
    EXPECT_EQ(a.instantRadiosity->causticLights, b.instantRadiosity->causticLights);
  }
  ASSERT_EQ(a.environments.size(), b.environments.size());
  for (size_t i = 0; i < a.environments.size(); ++i) {
    const EnvironmentDesc &x = a.environments[i], &y = b.environments[i];
    EXPECT_EQ(x.kind, y.kind);
    expectSameTexture(x.map, y.map, "environment map");
    EXPECT_EQ(x.colour, y.colour);
    EXPECT_EQ(x.intensity, y.intensity);
    EXPECT_EQ(x.up, y.up);
    EXPECT_EQ(x.rotateDegrees, y.rotateDegrees);
    EXPECT_EQ(x.lights, y.lights);
    EXPECT_EQ(x.visible, y.visible);
    EXPECT_EQ(x.sunDirection, y.sunDirection);
    EXPECT_EQ(x.turbidity, y.turbidity);
    EXPECT_EQ(x.ground, y.ground);
  }

  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    const ObjectDesc &x = a.objects[i], &y = b.objects[i];
    std::string w = "object " + std::to_string(i);
    EXPECT_EQ(x.kind, y.kind) << w;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) EXPECT_EQ(x.transform.m[size_t(r)][size_t(c)], y.transform.m[size_t(r)][size_t(c)]) << w;
    EXPECT_EQ(x.name, y.name) << w;
    EXPECT_EQ(x.capped, y.capped) << w;
    EXPECT_EQ(x.height, y.height) << w;
    EXPECT_EQ(x.bottomRadius, y.bottomRadius) << w;
    EXPECT_EQ(x.topRadius, y.topRadius) << w;
    expectSameMaterial(a.materials.at(size_t(x.material)), b.materials.at(size_t(y.material)), w + " material");
    ASSERT_EQ(x.mesh < 0, y.mesh < 0) << w;
    if (x.mesh < 0) continue;
    const MeshDesc &p = a.meshes.at(size_t(x.mesh)), &q = b.meshes.at(size_t(y.mesh));
    ASSERT_EQ(p.points.size(), q.points.size()) << w;
    for (size_t k = 0; k < p.points.size(); ++k) EXPECT_EQ(p.points[k], q.points[k]) << w;
    EXPECT_EQ(p.triangles, q.triangles) << w;
    ASSERT_EQ(p.normals.size(), q.normals.size()) << w;
    for (size_t k = 0; k < p.normals.size(); ++k) EXPECT_EQ(p.normals[k], q.normals[k]) << w;
    ASSERT_EQ(p.uvs.size(), q.uvs.size()) << w;
    for (size_t k = 0; k < p.uvs.size(); ++k) {
      EXPECT_EQ(p.uvs[k].x, q.uvs[k].x) << w;
      EXPECT_EQ(p.uvs[k].y, q.uvs[k].y) << w;
    }
    ASSERT_EQ(p.vertexMaterials.size(), q.vertexMaterials.size()) << w;
    for (size_t k = 0; k < p.vertexMaterials.size(); ++k)
      expectSameMaterial(a.materials.at(size_t(p.vertexMaterials[k])), b.materials.at(size_t(q.vertexMaterials[k])),
                         w + " vertex material " + std::to_string(k));
    EXPECT_EQ(p.triangleMaterials.size(), q.triangleMaterials.size()) << w;
    EXPECT_EQ(p.genNormals, q.genNormals) << w;
  }
}

std::string readAll(const std::string& path) { return lc::readFile(path); }

// parse -> write (into a temporary directory) -> parse, comparing the two scenes; also
// checks that writing the re-read scene gives the same text.
void roundTrip(const SceneDesc& original) {
  lc::testing::TempDir dir;
  RayWriteOptions opt;
  opt.relativeTo = dir.path();
  std::string out = dir.file("rt.ray");
  writeRayFile(out, original, opt);
  SceneDesc again = parseRayFile(out);
  EXPECT_TRUE(again.warnings.empty());
  expectSameScene(original, again);
  EXPECT_EQ(writeRayString(again, opt), readAll(out));
}

const char* kEverything = R"(SBT-raytracer 1.0
camera { position = (0.1, -2.5, 3e-3); look_at = (1, 1, 1); updir = (0, 0, 1); fov = 33.3; aspectratio = 1.7777778; }
ambient_light { colour = (0.1, 0.2, 0.3); }
ambient_light { color = (0.01, 0, 0); }
point_light { position = (1, 2, 3); colour = (0.7, 0.1, 0.9); constant_attenuation_coeff = 0.25;
  linear_attenuation_coeff = 0.003372407; quadratic_attenuation_coeff = 0.000045492; }
directional_light { direction = (-0.2, 0.2, -2); color = (.7, .7, .7); }
spot_light { position = (0, 3, 6); target = (0, 0, 0); color = (1, 0, 0); exponent = 3; cutoff = 45;
  cone_angle = 30; penumbra = 10; cutoff_distance = 500; }
spot_light { size = 50; blend = 0.15; direction = (0, -1, 0); }
instant_radiosity { vpls = 5000; bounces = 2; normalize = "object"; clamp = 0.05; seed = 12345678901234567; }
instant_radiosity { normalize = power; caustics = 700; caustic_lights = "vpl"; }
environment_light { map = "sky.exr"; colour = (1, 0.9, 0.8); intensity = 0.3; up = (0, 0, 1); rotate = 45; lights = 999; }
sun_sky_light { direction = (0.1, -0.7, 0.2); turbidity = 2.5; intensity = 3; ground = (0.1, 0.2, 0.3); visible = false; }
material = { name = shared; diffuse = (0.25, 0.5, 0.75); specular = map("spec.png"); shininess = 12.5; }
sphere { }
translate(1, 2, 3, rotate(1, 1, 0, 0.3, scale(0.1, 0.2, 0.3, {
  box { material = shared; name = "b ox"; }
  square { material = { emissive = (0.1, 0.1, 0.1); reflective = (0.5, 0.5, 0.5);
    transmissive = (0.2, 0.3, 0.4); index = 1.33; ambient = map("amb.bmp"); shininess = map("s.png"); index = map("i.png"); }; }
  material = { diffuse = (0.9, 0.1, 0.1); name = red; }
  cylinder { capped = false; }
  cone { height = 2; bottom_radius = 0.5; top_radius = 0.25; capped = false; }
})))
transform((0.628056, -0.777996, 0.027880, -0.003280), (0.209187, 0.189095, 1.631011, -0.191884),
  (-0.749525, -0.599137, 0.478565, -20.056301), (0, 0, 0, 1),
  polymesh { points = ((0,0,0), (1,0,0), (1,1,0), (0,1,0)); faces = ((0,1,2,3));
    normals = ((0,0,1), (0,0.6,0.8), (0.1,0.2,0.3), (0,0,1)); texcoords = ((0,0), (1,0), (1,1), (0.333333343,1));
    materials = ({ diffuse = (1,0,0); }, red, { name = vm; diffuse = (0,0,1); }, vm);
    gennormals; material = { luminosity = { colour = (1, 0.9, 0.7); intensity = 25; density = 4;
      constant_attenuation_coeff = 0.5; linear_attenuation_coeff = 0.1; quadratic_attenuation_coeff = 2; }; }; })
box { material = { diffuse = map("d.png"); luminosity = { colour = texture; }; }; }
box { material = { luminosity = { color = map("lum.png"); }; }; }
area_light { position = (4, 0, -4); u = (-1, 0, 1); v = (-0.5, 1, 0.5); color = (1.0, 0.5, 1.0); }
translate(0, 5, 0, sphere_light { emission = (3, 2, 1); radius = 0.5; })
)";

TEST(RayWriter, RoundTripsEveryFeature) {
  SceneDesc s = parseRayString(kEverything, "every.ray", "/scenes", {});
  // Sanity: the source exercises what it claims.
  ASSERT_EQ(s.objects.size(), 10u);
  ASSERT_EQ(s.lights.size(), 4u);
  ASSERT_TRUE(s.instantRadiosity);
  ASSERT_EQ(s.environments.size(), 2u);
  roundTrip(s);
}

TEST(RayWriter, RoundTripsEveryPublicScene) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(lc::testing::dataPath("public-scenes"))) {
    if (entry.path().extension() != ".ray") continue;
    SceneDesc s = parseRayFile(entry.path().string());  // strictly: emission is supported
    SCOPED_TRACE(entry.path().filename().string());
    roundTrip(s);
    ++count;
  }
  EXPECT_GE(count, 13);
}

TEST(RayWriter, HeaderAndStructure) {
  SceneDesc s = parseRayString("SBT-raytracer 1.0\ntranslate(0.1, 0, 0, sphere { name = x; })", "t.ray", "", {});
  std::string text = writeRayString(s);
  EXPECT_EQ(text.rfind("SBT-raytracer 1.0\n", 0), 0u);
  // Matrices are doubles, in the shortest form that reads back as the same double.
  EXPECT_NE(text.find("transform((1, 0, 0, 0.1), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1),"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("sphere {"), std::string::npos);
  EXPECT_NE(text.find("name = \"x\";"), std::string::npos);
  EXPECT_EQ(text.find("camera"), std::string::npos);  // no camera in the scene, none written
  EXPECT_EQ(text.find("ambient_light"), std::string::npos);
}

TEST(RayWriter, FloatsRoundTripExactly) {
  const float values[] = {0.1f, 1.0f / 3.0f, 1e-30f, 3.4028235e38f, 1.17549435e-38f, 1.4e-45f, -0.0f, 123456.789f,
                          0.000045492f, 16777217.0f};
  SceneDesc s;
  s.materials.resize(1);
  s.meshes.resize(1);
  for (float v : values) s.meshes[0].points.push_back(Vec3(v, -v, v * 0.5f));
  for (size_t i = 0; i + 2 < s.meshes[0].points.size(); ++i)
    s.meshes[0].triangles.push_back({int(i), int(i + 1), int(i + 2)});
  ObjectDesc o;
  o.kind = ShapeKind::Mesh;
  o.mesh = 0;
  o.transform = Mat4::rotate(0.3, 0.5, 0.7, 1.234567890123);
  s.objects.push_back(o);
  SceneDesc back = parseRayString(writeRayString(s), "w.ray", "", {});
  ASSERT_EQ(back.meshes.size(), 1u);
  for (size_t i = 0; i < s.meshes[0].points.size(); ++i) {
    EXPECT_EQ(back.meshes[0].points[i], s.meshes[0].points[i]) << i;
    EXPECT_EQ(std::signbit(back.meshes[0].points[i].x), std::signbit(s.meshes[0].points[i].x)) << i;
  }
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(back.objects[0].transform.m[size_t(r)][size_t(c)], o.transform.m[size_t(r)][size_t(c)]);
}

// Issue 26: floats are written in the shortest form that reads back as the same float,
// not with 9 digits of noise (0.63f used to be written 0.629999995).
TEST(RayWriter, FloatsAreWrittenInTheirShortestForm) {
  SceneDesc s;
  s.materials.resize(1);
  LightDesc l;
  l.kind = LightKind::Directional;
  l.direction = Vec3(0.63f, -0.1f, 1e-30f);
  l.colour = Color(1.0f / 3.0f, 100.0f, 16777216.0f);
  s.lights.push_back(l);
  std::string text = writeRayString(s);
  EXPECT_NE(text.find("direction = (0.63, -0.1, 1e-30);"), std::string::npos) << text;
  EXPECT_NE(text.find("colour = (0.33333334, 100, 16777216);"), std::string::npos) << text;

  // Every float reads back bit for bit: a spread of random bit patterns (all exponents,
  // denormals included) through the writer and the parser.
  SceneDesc m;
  m.materials.resize(1);
  m.meshes.resize(1);
  uint32_t x = 12345;
  auto next = [&] {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return x;
  };
  while (m.meshes[0].points.size() < 30000) {
    float f[3];
    for (float& v : f) {
      do {
        uint32_t bits = next();
        std::memcpy(&v, &bits, sizeof v);
      } while (!std::isfinite(v));
    }
    m.meshes[0].points.push_back(Vec3(f[0], f[1], f[2]));
  }
  m.meshes[0].triangles.push_back({0, 1, 2});
  ObjectDesc o;
  o.kind = ShapeKind::Mesh;
  o.mesh = 0;
  m.objects.push_back(o);
  SceneDesc back = parseRayString(writeRayString(m), "w.ray", "", {});
  ASSERT_EQ(back.meshes.size(), 1u);
  ASSERT_EQ(back.meshes[0].points.size(), m.meshes[0].points.size());
  for (size_t i = 0; i < m.meshes[0].points.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      float a = m.meshes[0].points[i][k], b = back.meshes[0].points[i][k];
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << i << " " << k << ": " << a << " read back as " << b;
    }
}

TEST(RayWriter, NonFiniteValuesAreErrors) {
  SceneDesc s;
  s.materials.resize(1);
  LightDesc l;
  l.colour = Color(std::numeric_limits<float>::quiet_NaN(), 0, 0);
  s.lights.push_back(l);
  EXPECT_THROW(writeRayString(s), Error);
  SceneDesc t;
  t.materials.resize(1);
  ObjectDesc o;
  o.transform.m[0][0] = std::numeric_limits<double>::infinity();
  t.objects.push_back(o);
  EXPECT_THROW(writeRayString(t), Error);
}

TEST(RayWriter, BadIndicesAreErrors) {
  SceneDesc s;
  s.materials.resize(1);
  ObjectDesc o;
  o.material = 3;
  s.objects.push_back(o);
  EXPECT_THROW(writeRayString(s), Error);
  s.objects[0].material = 0;
  s.objects[0].kind = ShapeKind::Mesh;
  s.objects[0].mesh = 0;
  EXPECT_THROW(writeRayString(s), Error);
}

TEST(RayWriter, FileIsWrittenAtomically) {
  lc::testing::TempDir dir;
  std::string path = dir.file("scene.ray");
  {
    std::ofstream f(path);
    f << "old contents";
  }
  SceneDesc bad;
  bad.materials.resize(1);
  bad.ambient = Color(std::numeric_limits<float>::infinity(), 0, 0);
  EXPECT_THROW(writeRayFile(path, bad), Error);
  EXPECT_EQ(readAll(path), "old contents");  // untouched on failure
  SceneDesc good = parseRayString("SBT-raytracer 1.0\nsphere {}", "t.ray", "", {});
  writeRayFile(path, good);
  EXPECT_EQ(readAll(path), writeRayString(good));
  // No temporary files left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  EXPECT_THROW(writeRayFile(dir.file("no/such/dir/x.ray"), good), Error);
}

TEST(RayWriter, TexturePathsRelativeToTheOutputDirectory) {
  SceneDesc s = parseRayString("SBT-raytracer 1.0\nbox { material = { diffuse = map(\"tex/a.png\"); }; }", "t.ray",
                               "/data/scenes", {});
  RayWriteOptions opt;
  opt.relativeTo = "/data/out";
  EXPECT_NE(writeRayString(s, opt).find("diffuse = map(\"../scenes/tex/a.png\");"), std::string::npos);
  opt.relativeTo = "/data/scenes";
  EXPECT_NE(writeRayString(s, opt).find("diffuse = map(\"tex/a.png\");"), std::string::npos);
  EXPECT_NE(writeRayString(s).find("diffuse = map(\"/data/scenes/tex/a.png\");"), std::string::npos);
  s.materials[1].diffuse.map->path = "bad\"name.png";
  EXPECT_THROW(writeRayString(s), Error);
}

TEST(RayWriter, SharedAndDuplicateNames) {
  // Two different materials with the same name (e.g. from two OBJ files) and a name that
  // cannot be quoted as is: the output must still parse.
  SceneDesc s;
  s.materials.resize(4);
  s.materials[1].name = "m";
  s.materials[1].diffuse.value = Color(1, 0, 0);
  s.materials[2].name = "m";
  s.materials[2].diffuse.value = Color(0, 1, 0);
  s.materials[3].name = "a\"b";
  for (int mat : {1, 2, 1, 3, 2}) {
    ObjectDesc o;
    o.material = mat;
    s.objects.push_back(o);
  }
  std::string text = writeRayString(s);
  SceneDesc back = parseRayString(text, "w.ray", "", {});
  ASSERT_EQ(back.objects.size(), 5u);
  auto diffuse = [&](size_t i) { return back.materials[size_t(back.objects[i].material)].diffuse.value; };
  EXPECT_EQ(diffuse(0), Color(1, 0, 0));
  EXPECT_EQ(diffuse(1), Color(0, 1, 0));
  EXPECT_EQ(diffuse(2), Color(1, 0, 0));
  EXPECT_EQ(diffuse(4), Color(0, 1, 0));
  EXPECT_EQ(back.objects[0].material, back.objects[2].material);  // declared once, then by name
  EXPECT_EQ(back.materials[size_t(back.objects[0].material)].name, "m");
  EXPECT_EQ(back.materials[size_t(back.objects[1].material)].name, "");  // the clash is written anonymously
  EXPECT_EQ(back.materials[size_t(back.objects[3].material)].name, "a_b");
}

TEST(RayWriter, PerTriangleMaterialsBecomeOneMeshPerMaterial) {
  SceneDesc s;
  s.materials.resize(3);
  s.materials[1].diffuse.value = Color(1, 0, 0);
  s.materials[2].diffuse.value = Color(0, 0, 1);
  MeshDesc m;
  m.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(2, 0, 0)};
  m.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1), Vec2(2, 0)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};
  m.triangleMaterials = {2, 1, 2};
  s.meshes.push_back(m);
  ObjectDesc o;
  o.kind = ShapeKind::Mesh;
  o.mesh = 0;
  o.transform = Mat4::translate(0, 0, 5);
  s.objects.push_back(o);
  SceneDesc back = parseRayString(writeRayString(s), "w.ray", "", {});
  ASSERT_EQ(back.objects.size(), 2u);
  // Ordered by material index: material 1 first.
  const MeshDesc& a = back.meshes[size_t(back.objects[0].mesh)];
  const MeshDesc& b = back.meshes[size_t(back.objects[1].mesh)];
  EXPECT_EQ(back.materials[size_t(back.objects[0].material)].diffuse.value, Color(1, 0, 0));
  EXPECT_EQ(back.materials[size_t(back.objects[1].material)].diffuse.value, Color(0, 0, 1));
  ASSERT_EQ(a.triangles.size(), 1u);
  ASSERT_EQ(a.points.size(), 3u);  // only the vertices it uses
  EXPECT_EQ(a.points[a.triangles[0][2]], Vec3(0, 1, 0));
  ASSERT_EQ(b.triangles.size(), 2u);
  ASSERT_EQ(b.points.size(), 4u);
  EXPECT_EQ(b.points[b.triangles[1][1]], Vec3(2, 0, 0));
  EXPECT_EQ(b.uvs[b.triangles[1][1]].x, 2.0f);
  EXPECT_EQ(back.objects[1].transform.m[2][3], 5.0);
}

TEST(RayWriter, BakedTransformsWriteWorldSpaceMeshes) {
  SceneDesc s = parseRayString(
      "SBT-raytracer 1.0\ntranslate(0, 0, 2, scale(1, 2, 1, trimesh { points = ((0,0,0),(1,0,0),(0,1,0));"
      " faces = ((0,1,2)); normals = ((1,1,0),(1,1,0),(1,1,0)); }))\nsphere {}",
      "t.ray", "", {});
  RayWriteOptions opt;
  opt.bakeTransforms = true;
  std::string text = writeRayString(s, opt);
  SceneDesc back = parseRayString(text, "w.ray", "", {});
  ASSERT_EQ(back.objects.size(), 2u);
  const ObjectDesc& o = back.objects[0];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(o.transform.m[size_t(r)][size_t(c)], r == c ? 1.0 : 0.0);
  const MeshDesc& m = back.meshes[size_t(o.mesh)];
  EXPECT_EQ(m.points[2], Vec3(0, 2, 2));
  EXPECT_EQ(m.points[1], Vec3(1, 0, 2));
  // Normals go through the inverse transpose: (1,1,0) under scale y=2 -> (1,0.5,0), normalised.
  EXPECT_NEAR(m.normals[0].x, 2 / std::sqrt(5.0f), 1e-6f);
  EXPECT_NEAR(m.normals[0].y, 1 / std::sqrt(5.0f), 1e-6f);
  // Quadrics keep their transform.
  EXPECT_EQ(back.objects[1].kind, ShapeKind::Sphere);
}

TEST(RayWriter, EmissiveWrittenOnlyWhenSet) {
  SceneDesc s = parseRayString("SBT-raytracer 1.0\nsphere { material = { diffuse = (1,1,1); }; }\n"
                               "sphere { material = { emissive = (0,0,0); }; }",
                               "t.ray", "", {});
  std::string text = writeRayString(s);
  size_t first = text.find("emissive");
  ASSERT_NE(first, std::string::npos);
  EXPECT_EQ(text.find("emissive", first + 1), std::string::npos);
  SceneDesc back = parseRayString(text, "w.ray", "", {});
  EXPECT_FALSE(back.materials[size_t(back.objects[0].material)].emissiveSet);
  EXPECT_TRUE(back.materials[size_t(back.objects[1].material)].emissiveSet);
}

}  // namespace
}  // namespace lc::io
