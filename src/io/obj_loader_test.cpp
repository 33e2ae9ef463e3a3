#include "io/obj_loader.h"

#include <gtest/gtest.h>

#include <filesystem>

#include <chrono>
#include <cmath>
#include <fstream>
#include <string>

#include "io/ray_parser.h"
#include "test_util.h"

namespace lc::io {
namespace {

using lc::testing::dataPath;
using lc::testing::TempDir;

ObjData load(const std::string& path, const Limits& limits = {}) {
  return loadObj(path, SourceLoc{}, MaterialDesc{}, limits);
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The message of the lc::Error that `fn` throws ("" when it throws none).
template <class Fn>
std::string errorOf(Fn&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool hasWarning(const std::vector<std::string>& warnings, const std::string& part) {
  for (const std::string& w : warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

void expectVec(const Vec3& v, float x, float y, float z) {
  EXPECT_FLOAT_EQ(v.x, x);
  EXPECT_FLOAT_EQ(v.y, y);
  EXPECT_FLOAT_EQ(v.z, z);
}

const MaterialDesc* findMaterial(const ObjData& d, const std::string& name) {
  for (const MaterialDesc& m : d.materials)
    if (m.name == name) return &m;
  return nullptr;
}

TEST(ObjLoader, NegativeIndicesReferToPrecedingVertices) {
  ObjData d = load(dataPath("obj/negative_indices.obj"));
  ASSERT_EQ(d.mesh.triangles.size(), 2u);
  ASSERT_EQ(d.mesh.points.size(), 4u);
  EXPECT_EQ(d.mesh.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(d.mesh.triangles[1], (std::array<int, 3>{1, 3, 2}));
  expectVec(d.mesh.points[3], 1, 1, 0);
  EXPECT_TRUE(d.mesh.normals.empty());
  EXPECT_TRUE(d.mesh.uvs.empty());
  EXPECT_FALSE(d.mesh.genNormals);
}

TEST(ObjLoader, QuadsBecomeTwoTrianglesAndPolygonsAreTriangulated) {
  ObjData d = load(dataPath("obj/quads.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 3u * 2u + 3u);
  EXPECT_EQ(d.mesh.points.size(), 13u);
  ASSERT_EQ(d.materials.size(), 1u);  // the default material
  EXPECT_FLOAT_EQ(d.materials[0].diffuse.value.x, 0.8f);
  EXPECT_EQ(d.mesh.triangleMaterials, std::vector<int>(9, 0));
  expectVec(d.bounds.lo, 0, 0, 0);
  expectVec(d.bounds.hi, 3.5f, 2, 1);
}

TEST(ObjLoader, MissingMaterialLibraryIsAWarning) {
  ObjData d = load(dataPath("obj/missing_mtl.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 1u);
  EXPECT_TRUE(hasWarning(d.warnings, "material library 'does_not_exist.mtl' not found"));
  ASSERT_EQ(d.materials.size(), 1u);
  EXPECT_EQ(d.materials[0].name, "");
  expectVec(d.materials[0].diffuse.value, 0.8f, 0.8f, 0.8f);
  EXPECT_EQ(d.mesh.triangleMaterials, std::vector<int>{0});
}

TEST(ObjLoader, MaterialLibraryThatIsADirectoryIsNamedSo) {
  // Issue 23 #10: it said "not found".
  TempDir dir;
  std::filesystem::create_directories(dir.file("lib.mtl"));
  writeText(dir.file("m.obj"), "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ObjData d = load(dir.file("m.obj"));
  EXPECT_TRUE(hasWarning(d.warnings, "material library 'lib.mtl' is a directory"));
  EXPECT_FALSE(hasWarning(d.warnings, "not found"));
  EXPECT_EQ(d.mesh.triangles.size(), 1u);
}

TEST(ObjLoader, MaterialLibraryFallsBackToTheFileBesideTheObj) {
  ObjData d = load(dataPath("obj/fallback/model.obj"));
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
  ASSERT_EQ(d.materials.size(), 1u);
  EXPECT_EQ(d.materials[0].name, "blue");
  expectVec(d.materials[0].diffuse.value, 0, 0, 1);
  EXPECT_EQ(d.materials[0].loc.file, dataPath("obj/fallback/fallback.mtl"));
  EXPECT_EQ(d.materials[0].loc.line, 1);
}

TEST(ObjLoader, WindowsSeparatorsInMtllib) {
  TempDir dir;
  std::filesystem::create_directory(dir.file("libs"));
  writeText(dir.file("libs/w.mtl"), "newmtl green\nKd 0 1 0\n");
  writeText(dir.file("m.obj"), "mtllib libs\\w.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl green\nf 1 2 3\n");
  ObjData d = load(dir.file("m.obj"));
  ASSERT_EQ(d.materials.size(), 1u);
  EXPECT_EQ(d.materials[0].name, "green");
  expectVec(d.materials[0].diffuse.value, 0, 1, 0);
}

TEST(ObjLoader, TextureNamesWithSpacesOptionsAndBackslashes) {
  ObjData d = load(dataPath("obj/textures.obj"));
  ASSERT_EQ(d.materials.size(), 5u);

  const MaterialDesc* spaces = findMaterial(d, "spaces");
  ASSERT_TRUE(spaces && spaces->diffuse.map);
  EXPECT_EQ(spaces->diffuse.map->path, dataPath("obj/my texture.png"));
  EXPECT_TRUE(spaces->diffuse.map->srgb);
  EXPECT_EQ(spaces->diffuse.map->loc.file, dataPath("obj/textures.mtl"));
  EXPECT_EQ(spaces->diffuse.map->loc.line, 4);

  const MaterialDesc* options = findMaterial(d, "options");
  ASSERT_TRUE(options && options->diffuse.map);
  EXPECT_EQ(options->diffuse.map->path, dataPath("obj/opt_tex.png"));
  expectVec(options->diffuse.value, 0.5f, 0.5f, 0.5f);

  const MaterialDesc* windows = findMaterial(d, "windows");
  ASSERT_TRUE(windows && windows->diffuse.map);
  EXPECT_EQ(windows->diffuse.map->path, dataPath("obj/sub/win.png"));
  expectVec(windows->diffuse.value, 0, 0, 0);  // no Kd: the base material's diffuse

  const MaterialDesc* missing = findMaterial(d, "missing");
  ASSERT_TRUE(missing);
  EXPECT_FALSE(missing->diffuse.map);
  expectVec(missing->diffuse.value, 0.2f, 0.3f, 0.4f);
  EXPECT_TRUE(hasWarning(d.warnings, "textures.mtl:18: warning: texture 'nothere.png' not found"));

  const MaterialDesc* glowing = findMaterial(d, "glowing");
  ASSERT_TRUE(glowing && glowing->luminosity && glowing->luminosity->colour.map);
  EXPECT_EQ(glowing->luminosity->colour.map->path, dataPath("obj/glow.png"));
  EXPECT_TRUE(glowing->luminosity->colour.map->srgb);

  EXPECT_EQ(d.mesh.uvs.size(), 3u);
}

TEST(ObjLoader, MaterialsStartFromTheBaseMaterial) {
  MaterialDesc base;
  base.specular = ColorParam{Color(0.25f, 0.25f, 0.25f), std::nullopt};
  base.name = "base";
  ObjData d = loadObj(dataPath("obj/textures.obj"), SourceLoc{}, base, Limits{});
  const MaterialDesc* spaces = findMaterial(d, "spaces");
  ASSERT_TRUE(spaces);
  expectVec(spaces->specular.value, 0.25f, 0.25f, 0.25f);
  expectVec(spaces->diffuse.value, 1, 1, 1);
}

TEST(ObjLoader, VerticesAreDistinctPositionUvNormalTuples) {
  ObjData d = load(dataPath("obj/dedupe.obj"));
  ASSERT_EQ(d.mesh.triangles.size(), 3u);
  EXPECT_EQ(d.mesh.points.size(), 7u);
  EXPECT_EQ(d.mesh.normals.size(), 7u);
  EXPECT_EQ(d.mesh.uvs.size(), 7u);
  EXPECT_EQ(d.mesh.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(d.mesh.triangles[1], (std::array<int, 3>{0, 2, 3}));
  EXPECT_EQ(d.mesh.triangles[2], (std::array<int, 3>{4, 5, 6}));
  expectVec(d.mesh.normals[4], 0, 0, -1);
  EXPECT_FLOAT_EQ(d.mesh.uvs[3].x, 0);
  EXPECT_FLOAT_EQ(d.mesh.uvs[3].y, 1);
  EXPECT_FALSE(d.mesh.genNormals);
}

TEST(ObjLoader, NormalsOnlyWhenEveryCornerHasOne) {
  ObjData d = load(dataPath("obj/partial_normals.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 3u);
  EXPECT_EQ(d.mesh.points.size(), 3u);  // vn no longer splits vertices
  EXPECT_TRUE(d.mesh.normals.empty());
  EXPECT_FALSE(d.mesh.genNormals);
  EXPECT_EQ(d.mesh.uvs.size(), 3u);
}

TEST(ObjLoader, KeBecomesALuminosity) {
  ObjData d = load(dataPath("obj/emissive.obj"));
  ASSERT_EQ(d.materials.size(), 2u);
  const MaterialDesc& lamp = d.materials[0];
  EXPECT_EQ(lamp.name, "lamp");
  ASSERT_TRUE(lamp.luminosity);
  expectVec(lamp.luminosity->colour.value, 1, 0.5f, 0.25f);
  EXPECT_FLOAT_EQ(lamp.luminosity->intensity, 4 * 2.0f);  // max(Ke) * area
  EXPECT_FLOAT_EQ(lamp.luminosity->density, 1000 / 2.0f);
  EXPECT_FLOAT_EQ(lamp.luminosity->attenQuadratic, 1);
  EXPECT_TRUE(lamp.emissiveSet);
  expectVec(lamp.emissive.value, 4, 2, 1);
  expectVec(lamp.diffuse.value, 0.5f, 0.5f, 0.5f);

  const MaterialDesc& dark = d.materials[1];
  EXPECT_FALSE(dark.luminosity);
  EXPECT_TRUE(dark.emissiveSet);
  expectVec(dark.emissive.value, 0, 0, 0);
  EXPECT_FLOAT_EQ(dark.shininess.value, 32);
  EXPECT_FLOAT_EQ(dark.index.value, 1.5f);
  expectVec(dark.transmissive.value, 0.75f, 0.75f, 0.75f);
  EXPECT_EQ(d.mesh.triangleMaterials, (std::vector<int>{0, 0, 1}));
}

TEST(ObjLoader, OutOfRangeIndexIsAnErrorWithItsLine) {
  std::string msg = errorOf([] { load(dataPath("obj/bad_index.obj")); });
  EXPECT_NE(msg.find("bad_index.obj:5: error: vertex index 9 is out of range: the file has 3 'v' lines"),
            std::string::npos)
      << msg;

  TempDir dir;
  writeText(dir.file("neg.obj"), "v 0 0 0\nv 1 0 0\nvt 0 0\nf -1/1 -2/1 -3/1\n");
  msg = errorOf([&] { load(dir.file("neg.obj")); });
  EXPECT_NE(msg.find("neg.obj:4: error: vertex index -3 is out of range: only 2 'v' lines precede it"),
            std::string::npos)
      << msg;

  writeText(dir.file("vn.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
  msg = errorOf([&] { load(dir.file("vn.obj")); });
  EXPECT_NE(msg.find("vn.obj:5: error: normal index 2 is out of range"), std::string::npos) << msg;

  writeText(dir.file("zero.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n");
  msg = errorOf([&] { load(dir.file("zero.obj")); });
  EXPECT_NE(msg.find("zero.obj:5: error: face has vertex index 0"), std::string::npos) << msg;
}

TEST(ObjLoader, NonFiniteCoordinatesAreErrors) {
  std::string msg = errorOf([] { load(dataPath("obj/nan_vertex.obj")); });
  EXPECT_NE(msg.find("nan_vertex.obj:2: error: vertex coordinate 'nan' is not a finite number"),
            std::string::npos)
      << msg;
  TempDir dir;
  writeText(dir.file("big.obj"), "v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n");
  msg = errorOf([&] { load(dir.file("big.obj")); });
  EXPECT_NE(msg.find("big.obj:3: error: vertex coordinate '1e39' is not a finite number"),
            std::string::npos)
      << msg;
  writeText(dir.file("vn.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn inf 0 1\nf 1//1 2//1 3//1\n");
  msg = errorOf([&] { load(dir.file("vn.obj")); });
  EXPECT_NE(msg.find("vn.obj:4: error: normal coordinate 'inf'"), std::string::npos) << msg;
}

TEST(ObjLoader, MissingFileNamesWhereItWasReferredFrom) {
  std::string missing = dataPath("obj/no_such_model.obj");
  std::string msg = errorOf([&] {
    loadObj(missing, SourceLoc{"scenes/x.ray", 12, 5}, MaterialDesc{}, Limits{});
  });
  EXPECT_EQ(msg, "scenes/x.ray:12:5: error: cannot open OBJ file '" + missing +
                     "': No such file or directory");
  msg = errorOf([&] { load(missing); });
  EXPECT_EQ(msg, "cannot open OBJ file '" + missing + "': No such file or directory");
}

TEST(ObjLoader, TriangleAndVertexLimits) {
  Limits limits;
  limits.maxTriangles = 8;
  std::string msg = errorOf([&] { load(dataPath("obj/quads.obj"), limits); });
  EXPECT_NE(msg.find("has 9 triangles, more than the limit of 8 (raise it with --max-triangles)"),
            std::string::npos)
      << msg;
  limits = Limits{};
  limits.maxVertices = 12;
  msg = errorOf([&] { load(dataPath("obj/quads.obj"), limits); });
  EXPECT_NE(msg.find("--max-triangles"), std::string::npos) << msg;
  limits.maxVertices = 13;
  EXPECT_EQ(load(dataPath("obj/quads.obj"), limits).mesh.points.size(), 13u);
}

TEST(ObjLoader, ParseErrorsCarryTheFileAndLine) {
  TempDir dir;
  writeText(dir.file("line.obj"), "v 0 0 0\nv 1 0 0\nl 1 0\n");
  std::string msg = errorOf([&] { load(dir.file("line.obj")); });
  EXPECT_NE(msg.find("line.obj:3: error: cannot parse OBJ file"), std::string::npos) << msg;
}

TEST(ObjLoader, McGuireCornellBox) {
  ObjData d = load(dataPath("models/CornellBox-Original.obj"));
  // 18 quads ('f' lines with 4 corners): 5 walls, 6 + 6 box faces, the light.
  EXPECT_EQ(d.mesh.triangles.size(), 36u);
  // 72 'v' lines; each box's last face reuses 4 vertices of an earlier face.
  EXPECT_EQ(d.mesh.points.size(), 64u);
  EXPECT_TRUE(d.mesh.normals.empty());
  EXPECT_TRUE(d.mesh.uvs.empty());
  EXPECT_EQ(d.materials.size(), 8u);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
  const MaterialDesc* light = findMaterial(d, "light");
  ASSERT_TRUE(light && light->luminosity);
  expectVec(light->luminosity->colour.value, 1, 12.0f / 17, 4.0f / 17);
  const double area = 0.47 * 0.38;
  EXPECT_NEAR(light->luminosity->intensity, 17 * area, 1e-4);
  EXPECT_NEAR(light->luminosity->density, 1000 / area, 0.1);
  expectVec(light->emissive.value, 17, 12, 4);
  int lightTris = 0;
  for (size_t t = 0; t < d.mesh.triangles.size(); ++t)
    if (&d.materials[size_t(d.mesh.triangleMaterials[t])] == light) ++lightTris;
  EXPECT_EQ(lightTris, 2);
  const MaterialDesc* left = findMaterial(d, "leftWall");
  ASSERT_TRUE(left);
  EXPECT_FALSE(left->luminosity);
  expectVec(left->diffuse.value, 0.63f, 0.065f, 0.05f);
  EXPECT_FLOAT_EQ(left->shininess.value, 10);
  expectVec(d.bounds.lo, -1.02f, 0, -1.04f);
  expectVec(d.bounds.hi, 1, 1.99f, 0.99f);
}

TEST(ObjLoader, GlossyCornellBoxFindsItsRepoRelativeMtl) {
  ObjData d = load(dataPath("models/CornellBox-Glossy.obj"));
  EXPECT_FALSE(hasWarning(d.warnings, "not found")) << d.warnings.front();
  const MaterialDesc* light = findMaterial(d, "light");
  ASSERT_TRUE(light && light->luminosity);
  EXPECT_EQ(d.materials.size(), 6u);  // the walls and the light (this copy has no boxes)
  const MaterialDesc* floor = findMaterial(d, "floor");
  ASSERT_TRUE(floor);
  expectVec(floor->diffuse.value, 0.725f, 0.71f, 0.68f);
  EXPECT_EQ(floor->loc.line, 49);
  // 12 triangles written as v/vt/vn with negative indices.
  EXPECT_EQ(d.mesh.triangles.size(), 12u);
  EXPECT_EQ(d.mesh.normals.size(), d.mesh.points.size());
  EXPECT_EQ(d.mesh.uvs.size(), d.mesh.points.size());
}

TEST(ObjLoader, CubeWithGroups) {
  ObjData d = load(dataPath("models/cube.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 12u);
  EXPECT_EQ(d.mesh.points.size(), 8u);
  ASSERT_EQ(d.materials.size(), 3u);  // white, red, green (blue and light unused)
  EXPECT_EQ(d.materials[0].name, "white");
  EXPECT_EQ(d.materials[1].name, "red");
  EXPECT_EQ(d.materials[2].name, "green");
  // front white, back (no usemtl: still white), right red, top white, left green, bottom white
  EXPECT_EQ(d.mesh.triangleMaterials,
            (std::vector<int>{0, 0, 0, 0, 1, 1, 0, 0, 2, 2, 0, 0}));
}

TEST(ObjLoader, SpiderHasUvsNormalsAndJpegMaps) {
  ObjData d = load(dataPath("models/assimp/spider.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 1368u);
  EXPECT_EQ(d.mesh.points.size(), 974u);
  EXPECT_EQ(d.mesh.uvs.size(), 974u);
  EXPECT_EQ(d.mesh.normals.size(), 974u);
  ASSERT_EQ(d.materials.size(), 4u);  // Brusttex is not used by any face
  const char* names[] = {"Skin", "HLeibTex", "BeinTex", "Augentex"};
  const char* maps[] = {"wal67ar_small.jpg", "SpiderTex.jpg", "drkwood2.jpg", "engineflare1.jpg"};
  for (int i = 0; i < 4; ++i) {
    const MaterialDesc& m = d.materials[size_t(i)];
    EXPECT_EQ(m.name, names[i]);
    ASSERT_TRUE(m.diffuse.map) << names[i];
    EXPECT_EQ(m.diffuse.map->path, dataPath(std::string("models/assimp/") + maps[i]));
    EXPECT_TRUE(m.diffuse.map->srgb);
  }
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

TEST(ObjLoader, MapBumpHasUvsAndNormals) {
  ObjData d = load(dataPath("models/map-bump.obj"));
  EXPECT_FALSE(d.mesh.uvs.empty());
  EXPECT_EQ(d.mesh.uvs.size(), d.mesh.points.size());
  EXPECT_EQ(d.mesh.normals.size(), d.mesh.points.size());
}

// CRLF line ends, comments, blank lines, tabs, and `o` / `g` / `s` statements change nothing.
TEST(ObjLoader, CrlfCommentsTabsAndGroupingStatements) {
  TempDir dir;
  writeText(dir.file("plain.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  writeText(dir.file("noisy.obj"),
            "# header comment\r\n\r\no thing\r\ng part one\r\ns 1\r\n"
            "v\t0 0 0\r\nv 1\t0 0   \r\n  v 1 1 0\r\nv 0 1 0 # trailing comment\r\n"
            "s off\r\nf 1\t2 3 4\r\n");
  ObjData a = load(dir.file("plain.obj")), b = load(dir.file("noisy.obj"));
  EXPECT_TRUE(b.warnings.empty()) << b.warnings.front();
  EXPECT_EQ(a.mesh.points, b.mesh.points);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(b.mesh.triangles.size(), 2u);
}

// Faces may mix positive and negative (relative) indices, also in one polygon; a
// pentagon becomes three triangles.
TEST(ObjLoader, MixedRelativeIndicesInAPolygon) {
  TempDir dir;
  writeText(dir.file("p.obj"),
            "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\n"
            "f 1 -4 3 -2 5\n");
  ObjData d = load(dir.file("p.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 3u);
  EXPECT_EQ(d.mesh.points.size(), 5u);
  double area = 0;
  for (const auto& t : d.mesh.triangles) {
    Vec3 e1 = d.mesh.points[size_t(t[1])] - d.mesh.points[size_t(t[0])];
    Vec3 e2 = d.mesh.points[size_t(t[2])] - d.mesh.points[size_t(t[0])];
    area += 0.5 * double(length(cross(e1, e2)));
  }
  EXPECT_NEAR(area, 5.0, 1e-5);  // the pentagon's area (shoelace formula)
}

// Optional extra components (`v x y z w`, vertex colours, `vt u v w`) are accepted and
// ignored.
TEST(ObjLoader, ExtraVertexComponentsAreIgnored) {
  TempDir dir;
  writeText(dir.file("x.obj"),
            "v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\n"
            "vt 0 0 0\nvt 1 0 0\nvt 0 1\nf 1/1 2/2 3/3\n");
  ObjData d = load(dir.file("x.obj"));
  ASSERT_EQ(d.mesh.points.size(), 3u);
  expectVec(d.mesh.points[1], 1, 0, 0);
  ASSERT_EQ(d.mesh.uvs.size(), 3u);
  EXPECT_FLOAT_EQ(d.mesh.uvs[1].x, 1);
  EXPECT_FLOAT_EQ(d.mesh.uvs[1].y, 0);
}

// One face without a vt drops the uvs of the whole mesh (and normals likewise), so no
// vertex is left with made-up coordinates.
TEST(ObjLoader, UvsOnlyWhenEveryCornerHasOne) {
  TempDir dir;
  writeText(dir.file("m.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
            "f 1/1/1 2/2/1 3/3/1\nf 1//1 3//1 2//1\n");
  ObjData d = load(dir.file("m.obj"));
  EXPECT_EQ(d.mesh.triangles.size(), 2u);
  EXPECT_TRUE(d.mesh.uvs.empty());
  EXPECT_EQ(d.mesh.normals.size(), d.mesh.points.size());
  EXPECT_EQ(d.mesh.points.size(), 3u);  // without uvs, (v, vn) alone tells vertices apart
}

// `usemtl` of a name the MTL does not define: a warning naming it, and the default material.
TEST(ObjLoader, UndefinedMaterialFallsBackToTheDefault) {
  TempDir dir;
  writeText(dir.file("m.mtl"), "newmtl red\nKd 1 0 0\n");
  writeText(dir.file("m.obj"),
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 3 2\n");
  ObjData d = load(dir.file("m.obj"));
  EXPECT_TRUE(hasWarning(d.warnings, "'blue' ] not found")) << (d.warnings.empty() ? "" : d.warnings[0]);
  ASSERT_EQ(d.mesh.triangleMaterials.size(), 2u);
  const MaterialDesc& red = d.materials.at(size_t(d.mesh.triangleMaterials[0]));
  const MaterialDesc& other = d.materials.at(size_t(d.mesh.triangleMaterials[1]));
  EXPECT_EQ(red.name, "red");
  EXPECT_EQ(other.name, "");
  expectVec(other.diffuse.value, 0.8f, 0.8f, 0.8f);
}

// Texture paths resolve against the MTL's folder, not the OBJ's; options and spaces combine.
TEST(ObjLoader, TexturePathsAreRelativeToTheMtl) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("mat/tex"));
  writeText(dir.file("mat/tex/a b.png"), "");  // only its existence matters to the loader
  writeText(dir.file("mat/m.mtl"), "newmtl t\nKd 1 1 1\nmap_Kd -s 2 2 1 -clamp on tex/a b.png\n");
  writeText(dir.file("m.obj"), "mtllib mat/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\nf 1 2 3\n");
  ObjData d = load(dir.file("m.obj"));
  ASSERT_EQ(d.materials.size(), 1u);
  ASSERT_TRUE(d.materials[0].diffuse.map) << (d.warnings.empty() ? "" : d.warnings[0]);
  EXPECT_TRUE(std::filesystem::equivalent(d.materials[0].diffuse.map->path, dir.file("mat/tex/a b.png")));
  EXPECT_EQ(d.materials[0].diffuse.map->loc.line, 3);
}

// A file with vertices but no faces loads as an empty mesh (the scene renders black).
TEST(ObjLoader, NoFacesIsAnEmptyMesh) {
  TempDir dir;
  writeText(dir.file("v.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ObjData d = load(dir.file("v.obj"));
  EXPECT_TRUE(d.mesh.triangles.empty());
  EXPECT_TRUE(d.mesh.points.empty());  // only vertices used by a face are kept
  EXPECT_EQ(d.materials.size(), 1u);
}

TEST(ObjScene, DefaultCameraAndLightRig) {
  std::string description;
  SceneDesc s = loadObjScene(dataPath("models/cube.obj"), Limits{}, &description);
  ASSERT_TRUE(s.hasCamera);
  ASSERT_EQ(s.materials.size(), 4u);  // the initial default, then white, red, green
  EXPECT_EQ(s.materials[1].name, "white");
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].kind, ShapeKind::Mesh);
  EXPECT_EQ(s.objects[0].mesh, 0);
  EXPECT_EQ(s.meshes[0].triangleMaterials[4], 2);  // red, shifted past the initial default
  // Bounds [0,2]^3: centre (1,1,1), radius sqrt(3), distance radius / sin(22.5 degrees).
  const float dist = std::sqrt(3.0f) / std::sin(22.5f * kPi / 180);
  EXPECT_NEAR(s.camera.position.x, 1, 1e-6);
  EXPECT_NEAR(s.camera.position.y, 1, 1e-6);
  EXPECT_NEAR(s.camera.position.z, 1 + dist, 1e-5);
  expectVec(s.camera.viewDir, 0, 0, -1);
  expectVec(s.camera.upDir, 0, 1, 0);
  EXPECT_FLOAT_EQ(s.camera.fovDegrees, 45);
  ASSERT_EQ(s.lights.size(), 2u);
  for (const LightDesc& l : s.lights) {
    EXPECT_EQ(l.kind, LightKind::Point);
    EXPECT_FLOAT_EQ(l.attenConstant, 1);
    EXPECT_FLOAT_EQ(l.attenLinear, 0);
    EXPECT_FLOAT_EQ(l.attenQuadratic, 0);
  }
  expectVec(s.lights[0].colour, 0.8f, 0.8f, 0.8f);
  expectVec(s.lights[1].colour, 0.3f, 0.3f, 0.3f);
  EXPECT_NE(description.find("camera {"), std::string::npos);
  EXPECT_NE(description.find("fov = 45;"), std::string::npos);
  EXPECT_NE(description.find("constant_attenuation_coeff = 1;"), std::string::npos);
  size_t lights = 0;
  for (size_t p = description.find("point_light {"); p != std::string::npos;
       p = description.find("point_light {", p + 1))
    ++lights;
  EXPECT_EQ(lights, 2u);
}

TEST(ObjScene, VerticesTooLargeForTheDefaultCameraNameTheirLine) {
  // Issue 23 #10: said "light parameters must be finite", with no file or line.
  TempDir dir;
  writeText(dir.file("huge.obj"), "v -1e38 -1e38 -1e38\nv 1 0 0\n# c\nv 1e38 1e38 2e38\nf 1 2 3\n");
  std::string msg = errorOf([&] { loadObjScene(dir.file("huge.obj"), Limits{}, nullptr); });
  EXPECT_NE(msg.find("huge.obj:4: error: vertex (1e38, 1e38, 2e38) is too far from the origin: the "
                     "default camera and lights for this model are out of range for a float"),
            std::string::npos)
      << msg;
  // Large but framable: loads.
  writeText(dir.file("big.obj"), "v -1e30 0 0\nv 1e30 0 0\nv 0 1e30 0\nf 1 2 3\n");
  EXPECT_NO_THROW(loadObjScene(dir.file("big.obj"), Limits{}, nullptr));
}

TEST(ObjScene, LuminousMaterialsReplaceTheLightRig) {
  std::string description;
  SceneDesc s = loadObjScene(dataPath("models/CornellBox-Original.obj"), Limits{}, &description);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.materials.size(), 9u);
  // The box is open towards +z: the camera looks from there.
  expectVec(s.camera.viewDir, 0, 0, -1);
  EXPECT_GT(s.camera.position.z, 0.99f);
  EXPECT_NE(description.find("1 luminous (Ke) material"), std::string::npos) << description;
  EXPECT_EQ(description.find("point_light"), std::string::npos);
}

TEST(ObjScene, CameraFacesTheOpenSide) {
  // The original Cornell data (tinyobj's copy) is open towards -z.
  SceneDesc s = loadObjScene(dataPath("models/tinyobj_cornell_box.obj"), Limits{}, nullptr);
  expectVec(s.camera.viewDir, 0, 0, 1);
  EXPECT_LT(s.camera.position.z, 0);
  EXPECT_EQ(s.lights.size(), 2u);  // Ka 20 is not an emitter
}

// obj2ray: the .ray reads back to the same triangles (one trimesh per material, in
// material order, each keeping its triangles' order), the same exact vertex data, and the
// same camera and lights.
void expectRoundTrip(const std::string& objPath, const std::string& rayName, size_t triangles) {
  TempDir dir;
  std::string rayPath = dir.file(rayName);
  writeRayFromObj(objPath, rayPath, Limits{});
  SceneDesc obj = loadObjScene(objPath, Limits{}, nullptr);
  SceneDesc ray = parseRayFile(rayPath);

  const MeshDesc& mesh = obj.meshes.at(0);
  ASSERT_EQ(mesh.triangles.size(), triangles);
  size_t parsedTriangles = 0;
  for (const MeshDesc& m : ray.meshes) parsedTriangles += m.triangles.size();
  EXPECT_EQ(parsedTriangles, triangles);

  // Walk the materials in order: object k of the .ray holds the k-th used material's
  // triangles, in their original order.
  size_t objectIndex = 0;
  for (int mi = 0; mi < int(obj.materials.size()); ++mi) {
    std::vector<size_t> tris;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (mesh.triangleMaterials[t] == mi) tris.push_back(t);
    if (tris.empty()) continue;
    ASSERT_LT(objectIndex, ray.objects.size());
    const ObjectDesc& o = ray.objects[objectIndex++];
    ASSERT_EQ(o.kind, ShapeKind::Mesh);
    const MeshDesc& part = ray.meshes.at(size_t(o.mesh));
    ASSERT_EQ(part.triangles.size(), tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      for (size_t c = 0; c < 3; ++c) {
        size_t a = size_t(mesh.triangles[tris[i]][c]), b = size_t(part.triangles[i][c]);
        ASSERT_EQ(mesh.points[a], part.points[b]) << "triangle " << tris[i] << " corner " << c;
        // Under the identity the writer copies normals as they are (no renormalising).
        if (!mesh.normals.empty()) {
          ASSERT_EQ(mesh.normals[a], part.normals.at(b));
        }
        if (!mesh.uvs.empty()) {
          ASSERT_EQ(mesh.uvs[a].x, part.uvs.at(b).x);
          ASSERT_EQ(mesh.uvs[a].y, part.uvs.at(b).y);
        }
      }
    }
    EXPECT_EQ(part.normals.size(), mesh.normals.empty() ? 0u : part.points.size());
    EXPECT_FALSE(part.genNormals);
    const MaterialDesc& want = obj.materials[size_t(mi)];
    const MaterialDesc& got = ray.materials.at(size_t(o.material));
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.diffuse.map.has_value(), want.diffuse.map.has_value());
    if (want.diffuse.map && got.diffuse.map) {
      EXPECT_TRUE(std::filesystem::equivalent(got.diffuse.map->path, want.diffuse.map->path));
    } else {
      EXPECT_EQ(got.diffuse.value, want.diffuse.value);  // a map replaces the constant
    }
    EXPECT_EQ(got.emissive.value, want.emissive.value);
    ASSERT_EQ(got.luminosity.has_value(), want.luminosity.has_value());
    if (want.luminosity) {
      EXPECT_EQ(got.luminosity->intensity, want.luminosity->intensity);
      EXPECT_EQ(got.luminosity->density, want.luminosity->density);
      EXPECT_EQ(got.luminosity->colour.map.has_value(), want.luminosity->colour.map.has_value());
      if (!want.luminosity->colour.map) {
        EXPECT_EQ(got.luminosity->colour.value, want.luminosity->colour.value);
      }
    }
  }
  EXPECT_EQ(objectIndex, ray.objects.size());

  ASSERT_TRUE(ray.hasCamera);
  EXPECT_EQ(ray.camera.position, obj.camera.position);
  EXPECT_EQ(ray.camera.viewDir, obj.camera.viewDir);
  EXPECT_EQ(ray.camera.upDir, obj.camera.upDir);
  EXPECT_EQ(ray.camera.fovDegrees, obj.camera.fovDegrees);
  ASSERT_EQ(ray.lights.size(), obj.lights.size());
  for (size_t i = 0; i < obj.lights.size(); ++i) {
    EXPECT_EQ(ray.lights[i].position, obj.lights[i].position);
    EXPECT_EQ(ray.lights[i].colour, obj.lights[i].colour);
    EXPECT_EQ(ray.lights[i].attenConstant, obj.lights[i].attenConstant);
    EXPECT_EQ(ray.lights[i].attenLinear, obj.lights[i].attenLinear);
    EXPECT_EQ(ray.lights[i].attenQuadratic, obj.lights[i].attenQuadratic);
  }
}

TEST(Obj2Ray, McGuireCornellBoxRoundTrips) {
  expectRoundTrip(dataPath("models/CornellBox-Original.obj"), "cornell.ray", 36);
}

TEST(Obj2Ray, SpiderRoundTripsWithUvsAndRelativeTextures) {
  expectRoundTrip(dataPath("models/assimp/spider.obj"), "spider.ray", 1368);
  // Textures are written relative to the .ray file's folder.
  TempDir dir;
  std::filesystem::create_directory(dir.file("out"));
  writeRayFromObj(dataPath("models/assimp/spider.obj"), dir.file("out/spider.ray"), Limits{});
  std::ifstream in(dir.file("out/spider.ray"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string rel = std::filesystem::path(dataPath("models/assimp/SpiderTex.jpg"))
                        .lexically_relative(std::filesystem::path(dir.file("out")))
                        .generic_string();
  EXPECT_NE(text.find("map(\"" + rel + "\")"), std::string::npos) << rel;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n') > 0, true);
  size_t trimeshes = 0;
  for (size_t p = text.find("trimesh {"); p != std::string::npos; p = text.find("trimesh {", p + 1))
    ++trimeshes;
  EXPECT_EQ(trimeshes, 4u);  // one per used material
}

TEST(Obj2Ray, CubeWithDefaultLightsRoundTrips) {
  expectRoundTrip(dataPath("models/cube.obj"), "cube.ray", 12);
}

TEST(Obj2Ray, TexturesAndEmissionMapRoundTrip) {
  expectRoundTrip(dataPath("obj/textures.obj"), "textures.ray", 5);
}

TEST(Obj2Ray, UnwritableOutputFailsBeforeLoading) {
  std::string msg = errorOf([] {
    writeRayFromObj(dataPath("obj/quads.obj"), "/nonexistent-dir/x.ray", Limits{});
  });
  EXPECT_NE(msg.find("cannot write '/nonexistent-dir/x.ray'"), std::string::npos) << msg;
}

// Issue 23: one polygon of 200,000 corners kept tinyobj's triangulation busy for minutes;
// faces of more than 4096 corners are refused by the pre-scan, with their line.
TEST(ObjLoader, HugePolygonIsRefusedQuickly) {
  TempDir dir;
  const int n = 100000;
  std::string text;
  text.reserve(size_t(n) * 40);
  for (int i = 0; i < n; ++i) {
    double a = 2 * 3.14159265358979 * i / n;
    text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  text += "f";
  for (int i = 1; i <= n; ++i) text += " " + std::to_string(i);
  text += "\n";
  std::string path = dir.file("huge.obj");
  writeText(path, text);
  auto t0 = std::chrono::steady_clock::now();
  std::string err = errorOf([&] { load(path); });
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(err.find("huge.obj:100001: error: face has 100000 vertices, more than 4096 in one polygon"),
            std::string::npos)
      << err;
  EXPECT_LT(seconds, 1.0);

  // 4096 corners still load (as 4094 triangles).
  std::string ok;
  for (int i = 0; i < 4096; ++i) {
    double a = 2 * 3.14159265358979 * i / 4096;
    ok += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  ok += "f";
  for (int i = 1; i <= 4096; ++i) ok += " " + std::to_string(i);
  ok += "\n";
  writeText(dir.file("ok.obj"), ok);
  EXPECT_EQ(errorOf([&] { load(dir.file("ok.obj")); }), "");
}

// An OBJ of several megabytes reaches tinyobj a block at a time (no copy of the text): every
// vertex and face arrives, and the progress it reports rises from 0 to 1.
TEST(ObjLoader, ALargeFileLoadsWholeAndReportsItsProgress) {
  TempDir dir;
  const std::string path = dir.file("grid.obj");
  constexpr int n = 300;  // 301^2 vertices, 2 * 300^2 triangles: about 4 MB of text
  {
    std::ofstream out(path);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) out << "v " << i * 0.01 << " " << (i * j % 7) * 0.001 << " " << j * 0.01 << "\n";
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * (n + 1) + i + 1;
        out << "f " << a << " " << a + 1 << " " << a + n + 2 << "\nf " << a << " " << a + n + 2 << " " << a + n + 1
            << "\n";
      }
  }
  ASSERT_GT(std::filesystem::file_size(path), 3u << 20);
  std::vector<double> seen;
  const ObjData d = loadObj(path, SourceLoc{}, MaterialDesc{}, Limits{}, [&](double f) { seen.push_back(f); });
  EXPECT_EQ(d.mesh.points.size(), size_t(n + 1) * size_t(n + 1));
  ASSERT_EQ(d.mesh.triangles.size(), size_t(2 * n * n));
  // The last face, as written.
  const int a = (n - 1) * (n + 1) + (n - 1);  // 0-based
  EXPECT_EQ(d.mesh.triangles.back()[1], a + n + 2);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
}

}  // namespace
}  // namespace lc::io
