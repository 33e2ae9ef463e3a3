#include "io/ray_parser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/file_util.h"
#include "io/obj_loader.h"
#include "test_util.h"

namespace lc::io {
namespace detail {
// Defined in ray_parser.cpp: merges a loaded OBJ into a scene.
void appendObjMesh(SceneDesc& scene, ObjData&& obj, ObjectDesc object, std::optional<int> overrideMaterial,
                   int defaultMaterial);
}  // namespace detail

namespace {

constexpr const char* kHeader = "SBT-raytracer 1.0\n";  // line 1; bodies start on line 2

SceneDesc parse(const std::string& body, const ParseOptions& o = {}) {
  return parseRayString(kHeader + body, "t.ray", "/base", o);
}

SceneDesc parseLenient(const std::string& body) {
  ParseOptions o;
  o.lenient = true;
  return parse(body, o);
}

// The full message ("t.ray:L:C: error: ...") of parsing `text` (with no header added).
std::string rawError(const std::string& text, const ParseOptions& o = {}) {
  try {
    parseRayString(text, "t.ray", "/base", o);
  } catch (const Error& e) {
    return e.what();
  }
  return "<no error>";
}
std::string error(const std::string& body, const ParseOptions& o = {}) { return rawError(kHeader + body, o); }

void expectVec(const Vec3& v, float x, float y, float z, float tol = 0) {
  EXPECT_NEAR(v.x, x, tol);
  EXPECT_NEAR(v.y, y, tol);
  EXPECT_NEAR(v.z, z, tol);
}

const MaterialDesc& materialOf(const SceneDesc& s, size_t object) {
  return s.materials.at(size_t(s.objects.at(object).material));
}

// ---------------------------------------------------------------------------------------
// Header, top level, malformed files

TEST(RayParserHeader, HeaderOnlyGivesAnEmptySceneWithTheDefaultMaterial) {
  SceneDesc s = parseRayString("SBT-raytracer 1.0", "t.ray", "", {});
  EXPECT_EQ(s.path, "t.ray");
  EXPECT_FALSE(s.hasCamera);
  EXPECT_TRUE(s.objects.empty());
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].index.value, 1.0f);
  EXPECT_EQ(s.materials[0].shininess.value, 0.0f);
  EXPECT_TRUE(isBlack(s.materials[0].diffuse.value));
  expectVec(s.ambient, 0, 0, 0);
  EXPECT_FALSE(s.instantRadiosity);
  // Camera defaults when the scene has none.
  expectVec(s.camera.viewDir, 0, 0, -1);
  expectVec(s.camera.upDir, 0, 1, 0);
  EXPECT_NEAR(s.camera.fovDegrees, 53.130102f, 1e-5f);
}

TEST(RayParserHeader, VersionsAndComments) {
  EXPECT_NO_THROW(parseRayString("SBT-raytracer 1.1\n", "t.ray", "", {}));
  EXPECT_NO_THROW(parseRayString("// leading comment\n/* block */ SBT-raytracer 1.0", "t.ray", "", {}));
}

TEST(RayParserHeader, EmptyFile) {
  EXPECT_EQ(rawError(""), "t.ray:1:1: error: expected the header 'SBT-raytracer 1.0', got end of file");
  EXPECT_EQ(rawError("  \n// only a comment\n"),
            "t.ray:3:1: error: expected the header 'SBT-raytracer 1.0', got end of file");
}

TEST(RayParserHeader, MissingHeader) {
  EXPECT_EQ(rawError("camera { }"), "t.ray:1:1: error: expected the header 'SBT-raytracer 1.0', got 'camera'");
  EXPECT_EQ(rawError("\"SBT-raytracer\" 1.0"),
            "t.ray:1:1: error: expected the header 'SBT-raytracer 1.0', got string \"SBT-raytracer\"");
}

TEST(RayParserHeader, MissingVersion) {
  EXPECT_EQ(rawError("SBT-raytracer\ncamera {}"),
            "t.ray:2:1: error: expected a version number after 'SBT-raytracer', got 'camera'");
}

TEST(RayParserTopLevel, LoneSemicolonsAreAllowed) {
  SceneDesc s = parse(";;\nsphere {};;\n;");
  EXPECT_EQ(s.objects.size(), 1u);
}

TEST(RayParserTopLevel, StrayClosingBrace) {
  EXPECT_EQ(error("sphere {}\n}"), "t.ray:3:1: error: unexpected '}' (no block is open)");
}

TEST(RayParserTopLevel, EndOfFileInsideBlocks) {
  EXPECT_EQ(error("camera {\n  position = (1,2,3);"),
            "t.ray:3:22: error: expected '}' to close camera opened at 2:8, got end of file");
  EXPECT_EQ(error("sphere { material = { diffuse = (1,1,1);"),
            "t.ray:2:41: error: expected '}' to close material opened at 2:21, got end of file");
  EXPECT_EQ(error("translate(1,2,3, sphere {}"),
            "t.ray:2:27: error: expected ')' to close translate opened at 2:1, got end of file");
  EXPECT_EQ(error("{ sphere {}"), "t.ray:2:12: error: expected '}' to close the group opened at 2:1, got end of file");
  EXPECT_EQ(error("camera { position = (1,2"), "t.ray:2:25: error: expected ',' or ')', got end of file");
  EXPECT_EQ(error("camera"), "t.ray:2:7: error: expected '{' after camera, got end of file");
}

TEST(RayParserTopLevel, NonItemTokens) {
  EXPECT_EQ(error("\n  42"), "t.ray:3:3: error: expected a scene item (camera, light, material or object), got number 42");
  EXPECT_EQ(error("= sphere"), "t.ray:2:1: error: expected a scene item (camera, light, material or object), got '='");
}

TEST(RayParserTopLevel, UnknownTopLevelKeyword) {
  EXPECT_EQ(error("fog { density = 1; }"), "t.ray:2:1: error: unknown keyword 'fog'");
  SceneDesc s = parseLenient("fog { density = 1; }\nsphere {}");
  EXPECT_EQ(s.objects.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "t.ray:2:1: warning: unknown keyword 'fog' (skipped)");
}

// ---------------------------------------------------------------------------------------
// Numbers and tuples

TEST(RayParserValues, NumbersMustBeFinite) {
  EXPECT_EQ(error("camera { position = (1, 1e999, 0); }"), "t.ray:2:25: error: number '1e999' is out of range");
  // Finite as a double but not as a float.
  EXPECT_EQ(error("camera { position = (1, 1e39, 0); }"),
            "t.ray:2:25: error: number 1e39 is out of range for a float");
  // Transforms keep doubles, but coordinates are bounded (below).
  SceneDesc s = parse("translate(1e15, 0, 0, sphere {})");
  EXPECT_EQ(s.objects[0].transform.m[0][3], 1e15);
  // Words that other languages read as numbers are not numbers here.
  EXPECT_EQ(error("camera { fov = inf; }"), "t.ray:2:16: error: expected a number, got 'inf'");
  EXPECT_EQ(error("camera { fov = nan; }"), "t.ray:2:16: error: expected a number, got 'nan'");
}

// Issue 23: positions, directions and transform entries beyond 1e15 in magnitude are refused
// at the number (Embree aborts on rays whose origin lies beyond ~1.8e18); so is an index that
// makes refraction degenerate.
TEST(RayParserValues, CoordinatesAreBounded) {
  const std::string tail = " is too large for a coordinate (at most 1e15 in magnitude)";
  EXPECT_EQ(error("camera { position = (0,0,1e19); }"), "t.ray:2:26: error: number 1e19" + tail);
  EXPECT_EQ(error("camera { look_at = (0,-2e15,0); }"), "t.ray:2:23: error: number -2e15" + tail);
  EXPECT_EQ(error("camera { viewdir = (1e16,0,0); }"), "t.ray:2:21: error: number 1e16" + tail);
  EXPECT_EQ(error("camera { updir = (0,1e16,0); }"), "t.ray:2:21: error: number 1e16" + tail);
  EXPECT_EQ(error("point_light { position = (1e16,0,0); }"), "t.ray:2:27: error: number 1e16" + tail);
  EXPECT_EQ(error("directional_light { direction = (0,0,-1e16); }"), "t.ray:2:38: error: number -1e16" + tail);
  EXPECT_EQ(error("spot_light { target = (0,0,1e16); }"), "t.ray:2:28: error: number 1e16" + tail);
  EXPECT_EQ(error("area_light { position = (1e16,0,0); u = (1,0,0); v = (0,1,0); }"),
            "t.ray:2:26: error: number 1e16" + tail);
  EXPECT_EQ(error("translate(1e19, 0, 0, sphere {})"), "t.ray:2:11: error: number 1e19" + tail);
  EXPECT_EQ(error("scale(1e16, sphere {})"), "t.ray:2:7: error: number 1e16" + tail);
  EXPECT_EQ(error("transform((1,0,0,1e16),(0,1,0,0),(0,0,1,0),(0,0,0,1), sphere {})"),
            "t.ray:2:18: error: number 1e16" + tail);
  EXPECT_EQ(error("sphere { material = { transmissive = (1,1,1); index = 1e20; }; }"),
            "t.ray:2:55: error: index must be at most 1000, got 1e20");
  // The bound itself is fine; colours are not coordinates, and mesh points (like OBJ vertices)
  // are only bounded by the float range: the renderer drops rays that leave Embree's range.
  EXPECT_NO_THROW(parse("trimesh { points = ((0,0,0),(1e30,0,0),(0,1,0)); faces = ((0,1,2)); }"));
  EXPECT_NO_THROW(parse("camera { position = (0,0,1e15); }\npoint_light { colour = (1e30,1,1); }"));
}

// Issue 23: identifiers, strings and paths in messages are shortened and escaped.
TEST(RayParserValues, MessagesQuoteInputSafely) {
  std::string longName(100000, 'q');
  std::string e = error(longName + " {}");
  EXPECT_EQ(e, "t.ray:2:1: error: unknown keyword '" + std::string(80, 'q') + "...'");
  EXPECT_EQ(error("camera { position = \"a\x1b[2Jb\"; }"), "t.ray:2:21: error: expected '(', got string \"a\\x1b[2Jb\"");
  EXPECT_EQ(error("camera { position = \"x\ty\"; }"), "t.ray:2:21: error: expected '(', got string \"x\\ty\"");
}

TEST(RayParserValues, TupleArity) {
  EXPECT_EQ(error("camera {\n  position = (1,2);\n}"), "t.ray:3:14: error: expected 3 numbers, got 2");
  EXPECT_EQ(error("camera { position = (1,2,3,4); }"), "t.ray:2:21: error: expected 3 numbers, got 4");
  EXPECT_EQ(error("camera { position = (); }"), "t.ray:2:21: error: expected 3 numbers, got 0");
  EXPECT_EQ(error("camera { quaternion = (1,2,3); }"), "t.ray:2:23: error: expected 4 numbers, got 3");
  EXPECT_EQ(error("transform((1,0,0,0),(0,1,0),(0,0,1,0),(0,0,0,1), sphere{})"),
            "t.ray:2:21: error: expected 4 numbers, got 3");
}

TEST(RayParserValues, UnexpectedTokens) {
  EXPECT_EQ(error("camera { position = (1, a, 2); }"), "t.ray:2:25: error: expected a number, got 'a'");
  EXPECT_EQ(error("camera { position (1,2,3); }"), "t.ray:2:19: error: expected '=', got '('");
  EXPECT_EQ(error("camera { position = 1; }"), "t.ray:2:21: error: expected '(', got number 1");
  EXPECT_EQ(error("camera { position = (1 2 3); }"), "t.ray:2:24: error: expected ',' or ')', got number 2");
  EXPECT_EQ(error("camera { 3 }"), "t.ray:2:10: error: expected an attribute name or '}' in camera, got number 3");
  EXPECT_EQ(error("sphere { material = { diffuse = 0.5; } }"),
            "t.ray:2:33: error: expected a colour (r,g,b) or map(\"file\"), got number 0.5");
  EXPECT_EQ(error("cylinder { capped = 1; }"), "t.ray:2:21: error: expected true or false, got number 1");
}

TEST(RayParserValues, SemicolonsAreOptional) {
  SceneDesc s = parse("camera { position = (1,2,3) fov = 30 aspectratio = 2 }\n"
                      "point_light { position = (0,1,0) colour = (1,0,0) }");
  expectVec(s.camera.position, 1, 2, 3);
  EXPECT_EQ(s.camera.fovDegrees, 30.0f);
  EXPECT_EQ(*s.camera.aspectRatio, 2.0f);
  EXPECT_EQ(s.lights.size(), 1u);
}

// ---------------------------------------------------------------------------------------
// Camera

TEST(RayParserCamera, AllFields) {
  SceneDesc s = parse("camera {\n position = (1,2,3);\n viewdir = (0,0,1);\n updir = (0,2,0);\n fov = 45;\n"
                      " aspectratio = 1.5;\n}");
  ASSERT_TRUE(s.hasCamera);
  expectVec(s.camera.position, 1, 2, 3);
  expectVec(s.camera.viewDir, 0, 0, 1);
  expectVec(s.camera.upDir, 0, 2, 0);
  EXPECT_EQ(s.camera.fovDegrees, 45.0f);
  ASSERT_TRUE(s.camera.aspectRatio);
  EXPECT_EQ(*s.camera.aspectRatio, 1.5f);
  EXPECT_EQ(s.camera.loc.line, 2);
  EXPECT_EQ(s.camera.loc.column, 1);
}

TEST(RayParserCamera, EmptyCameraKeepsDefaults) {
  SceneDesc s = parse("camera { }");
  EXPECT_TRUE(s.hasCamera);
  expectVec(s.camera.position, 0, 0, 0);
  expectVec(s.camera.viewDir, 0, 0, -1);
  EXPECT_FALSE(s.camera.aspectRatio);
}

TEST(RayParserCamera, LookAt) {
  SceneDesc s = parse("camera { look_at = (1, 2, -7); position = (1, 2, 3); }");
  expectVec(s.camera.viewDir, 0, 0, -10);  // resolved at the '}', after position
  SceneDesc t = parse("camera { look_at = (0,0,5); viewdir = (1,0,0); }");  // the later one wins
  expectVec(t.camera.viewDir, 1, 0, 0);
  EXPECT_EQ(error("camera { position = (1,1,1);\n look_at = (1,1,1); }"),
            "t.ray:3:12: error: look_at must differ from the camera position");
}

TEST(RayParserCamera, QuaternionRotatesTheDefaultFrame) {
  // 90 degrees about +y: the view (-z) turns to -x, up stays +y.
  SceneDesc s = parse("camera { quaternion = (0, 0.70710678, 0, 0.70710678); }");
  expectVec(s.camera.viewDir, -1, 0, 0, 1e-6f);
  expectVec(s.camera.upDir, 0, 1, 0, 1e-6f);
  // 90 degrees about +x (not normalised on input): view -z -> +y, up +y -> +z.
  SceneDesc t = parse("camera { quaternian = (2, 0, 0, 2); }");  // the historical spelling
  expectVec(t.camera.viewDir, 0, 1, 0, 1e-6f);
  expectVec(t.camera.upDir, 0, 0, 1, 1e-6f);
  // Identity.
  SceneDesc u = parse("camera { quaternion = (0,0,0,1); }");
  expectVec(u.camera.viewDir, 0, 0, -1);
  expectVec(u.camera.upDir, 0, 1, 0);
  EXPECT_EQ(error("camera { quaternion = (0,0,0,0); }"), "t.ray:2:23: error: quaternion must not be zero");
}

TEST(RayParserCamera, InvalidDirections) {
  EXPECT_EQ(error("camera {\n viewdir = (0,0,0); }"), "t.ray:3:12: error: viewdir must not be zero");
  EXPECT_EQ(error("camera { updir = (0,0,0); }"), "t.ray:2:18: error: updir must not be zero");
  EXPECT_EQ(error("camera { viewdir = (0,2,0);\n  updir = (0,-1,0); }"),
            "t.ray:3:11: error: viewdir and updir are parallel");
  // Parallel with the default updir: reported at viewdir.
  EXPECT_EQ(error("camera { viewdir = (0,1,0); }"), "t.ray:2:20: error: viewdir and updir are parallel");
}

TEST(RayParserCamera, HugeAndTinyDirectionsAreNotParallelOrZero) {
  // Issue 23 #10: (0,0,-1e20) said "parallel" (its squared length overflowed); now the
  // coordinate limit names the real problem, and what passes it normalises safely.
  EXPECT_EQ(error("camera { viewdir = (0,0,-1e20); }"),
            "t.ray:2:25: error: number -1e20 is too large for a coordinate (at most 1e15 in magnitude)");
  SceneDesc a = parse("camera { viewdir = (0,0,-1e15); updir = (0,1e15,1e15); }");
  expectVec(a.camera.viewDir, 0, 0, -1e15f);
  // Tiny components underflow the squared length: not zero, not parallel.
  SceneDesc b = parse("camera { viewdir = (1e-30,0,0); updir = (0,1e-30,0); }");
  expectVec(b.camera.viewDir, 1e-30f, 0, 0);
  SceneDesc c = parse("directional_light { direction = (1e-30,0,-1e-30); }");
  ASSERT_EQ(c.lights.size(), 1u);
}

TEST(RayParserCamera, InvalidFovAndAspect) {
  EXPECT_EQ(error("camera { fov = 180; }"), "t.ray:2:16: error: fov must be between 0 and 180 degrees, got 180");
  EXPECT_EQ(error("camera { fov = -5; }"), "t.ray:2:16: error: fov must be between 0 and 180 degrees, got -5");
  // Issue 23 #10: in range as written, 180 as a float; the message says both.
  EXPECT_EQ(error("camera { fov = 179.99999999; }"),
            "t.ray:2:16: error: fov must be between 0 and 180 degrees, got 180 (179.99999999 rounds to "
            "180 in single precision)");
  EXPECT_EQ(error("camera { fov = 1e-50; }"),
            "t.ray:2:16: error: fov must be between 0 and 180 degrees, got 0 (1e-50 rounds to 0 in "
            "single precision)");
  EXPECT_FLOAT_EQ(parse("camera { fov = 179.9999; }").camera.fovDegrees, 179.9999f);
  EXPECT_EQ(error("camera { aspectratio = 0; }"), "t.ray:2:24: error: aspectratio must be > 0, got 0");
}

TEST(RayParserCamera, SecondCameraIsAnError) {
  EXPECT_EQ(error("camera {}\ncamera {}"), "t.ray:3:1: error: a second camera (the first is at 2:1)");
}

TEST(RayParserCamera, UnknownAttribute) {
  EXPECT_EQ(error("camera { zoom = 2; }"), "t.ray:2:10: error: unknown keyword 'zoom' in camera");
  SceneDesc s = parseLenient("camera { zoom = 2; fov = 20; }");
  EXPECT_EQ(s.camera.fovDegrees, 20.0f);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "t.ray:2:10: warning: unknown keyword 'zoom' in camera (skipped)");
}

// ---------------------------------------------------------------------------------------
// Materials

TEST(RayParserMaterial, AllFields) {
  SceneDesc s = parse(
      "sphere { material = {\n"
      "  emissive = (0.1, 0.2, 0.3);\n"
      "  ambient = (0.4, 0.5, 0.6);\n"
      "  diffuse = (0.7, 0.8, 0.9);\n"
      "  specular = (1, 0.5, 0.25);\n"
      "  reflective = (0.125, 0, 1);\n"
      "  transmissive = (0.3, 0.3, 0.3);\n"
      "  shininess = 25.6;\n"
      "  index = 1.5;\n"
      "}; }");
  ASSERT_EQ(s.objects.size(), 1u);
  const MaterialDesc& m = materialOf(s, 0);
  expectVec(m.emissive.value, 0.1f, 0.2f, 0.3f);
  EXPECT_TRUE(m.emissiveSet);
  expectVec(m.ambient.value, 0.4f, 0.5f, 0.6f);
  expectVec(m.diffuse.value, 0.7f, 0.8f, 0.9f);
  expectVec(m.specular.value, 1, 0.5f, 0.25f);
  expectVec(m.reflective.value, 0.125f, 0, 1);
  expectVec(m.transmissive.value, 0.3f, 0.3f, 0.3f);
  EXPECT_EQ(m.shininess.value, 25.6f);
  EXPECT_EQ(m.index.value, 1.5f);
  EXPECT_FALSE(m.diffuse.map);
  EXPECT_FALSE(m.luminosity);
  EXPECT_EQ(m.loc.line, 2);
  EXPECT_EQ(m.loc.column, 21);
  EXPECT_EQ(s.materials.size(), 2u);  // the default and this one
}

TEST(RayParserMaterial, DefaultsAndEmissiveSet) {
  SceneDesc s = parse("sphere { material = { diffuse = (1,0,0); }; }");
  const MaterialDesc& m = materialOf(s, 0);
  EXPECT_FALSE(m.emissiveSet);
  EXPECT_TRUE(isBlack(m.emissive.value));
  EXPECT_TRUE(isBlack(m.specular.value));
  EXPECT_EQ(m.index.value, 1.0f);
  EXPECT_EQ(m.shininess.value, 0.0f);
  // An explicit black emissive still counts as set.
  SceneDesc t = parse("sphere { material = { emissive = (0,0,0); }; }");
  EXPECT_TRUE(materialOf(t, 0).emissiveSet);
}

TEST(RayParserMaterial, TextureMaps) {
  SceneDesc s = parse("box { material = {\n  diffuse = map(\"tex/checker.bmp\");\n  specular = map(specmap);\n"
                      "  shininess = map(\"rough.png\");\n  index = map(\"/abs/ior.png\"); }; }");
  const MaterialDesc& m = materialOf(s, 0);
  ASSERT_TRUE(m.diffuse.map);
  EXPECT_EQ(m.diffuse.map->path, "/base/tex/checker.bmp");
  EXPECT_EQ(m.diffuse.map->loc.file, "t.ray");
  EXPECT_EQ(m.diffuse.map->loc.line, 3);
  EXPECT_EQ(m.diffuse.map->loc.column, 13);
  EXPECT_TRUE(m.diffuse.map->srgb);  // a colour map: sRGB (linearised for display-encoded output)
  ASSERT_TRUE(m.specular.map);
  EXPECT_TRUE(m.specular.map->srgb);
  EXPECT_EQ(m.specular.map->path, "/base/specmap");
  ASSERT_TRUE(m.shininess.map);
  EXPECT_EQ(m.shininess.map->path, "/base/rough.png");
  EXPECT_EQ(m.shininess.map->loc.line, 5);
  EXPECT_EQ(m.shininess.map->loc.column, 15);
  ASSERT_TRUE(m.index.map);
  EXPECT_EQ(m.index.map->path, "/abs/ior.png");  // absolute paths are kept
  EXPECT_FALSE(m.shininess.map->srgb);  // scalar maps are values
  EXPECT_FALSE(m.index.map->srgb);
  // A relative base directory joins too; an empty one leaves the path as written.
  SceneDesc r = parseRayString(std::string(kHeader) + "box { material = { diffuse = map(\"a.bmp\"); }; }",
                               "x.ray", "scenes/sub", {});
  EXPECT_EQ(materialOf(r, 0).diffuse.map->path, "scenes/sub/a.bmp");
  SceneDesc e = parseRayString(std::string(kHeader) + "box { material = { diffuse = map(\"a.bmp\"); }; }",
                               "x.ray", "", {});
  EXPECT_EQ(materialOf(e, 0).diffuse.map->path, "a.bmp");
}

TEST(RayParserMaterial, MapErrors) {
  EXPECT_EQ(error("box { material = { diffuse = map(\"\"); }; }"), "t.ray:2:34: error: empty texture file name");
  EXPECT_EQ(error("box { material = { diffuse = map(3); }; }"), "t.ray:2:34: error: expected a file name, got number 3");
  EXPECT_EQ(error("box { material = { diffuse = map \"a\"; }; }"), "t.ray:2:34: error: expected '(', got string \"a\"");
  EXPECT_EQ(error("box { material = { shininess = (1,2,3); }; }"),
            "t.ray:2:32: error: expected a number or map(\"file\"), got '('");
}

TEST(RayParserMaterial, ScalarRanges) {
  EXPECT_EQ(error("box { material = { shininess = -1; }; }"), "t.ray:2:32: error: shininess must be >= 0, got -1");
  EXPECT_EQ(error("box { material = { index = 0; }; }"), "t.ray:2:28: error: index must be > 0, got 0");
}

TEST(RayParserMaterial, NamedMaterialsAllThreeForms) {
  SceneDesc s = parse(
      "material = { name red; diffuse = (1,0,0); }\n"
      "material = { name = green; diffuse = (0,1,0); }\n"
      "material = { name = \"blue sky\"; diffuse = (0,0,1); }\n"
      "sphere { material = red; }\n"
      "sphere { material = green; }\n"
      "sphere { material = \"blue sky\"; }\n");
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(materialOf(s, 0).name, "red");
  expectVec(materialOf(s, 0).diffuse.value, 1, 0, 0);
  EXPECT_EQ(materialOf(s, 1).name, "green");
  expectVec(materialOf(s, 1).diffuse.value, 0, 1, 0);
  EXPECT_EQ(materialOf(s, 2).name, "blue sky");
  expectVec(materialOf(s, 2).diffuse.value, 0, 0, 1);
  // References share one entry.
  SceneDesc t = parse("sphere { material = { name m; diffuse = (1,1,0); }; }\nbox { material = m; }");
  EXPECT_EQ(t.objects[0].material, t.objects[1].material);
}

TEST(RayParserMaterial, DuplicateAndUnknownNames) {
  EXPECT_EQ(error("material = { name = m; }\nsphere { material = {\n  name = m; }; }"),
            "t.ray:4:10: error: material 'm' is already declared (at t.ray:2:12)");
  EXPECT_EQ(error("sphere {\n material = nosuch; }"), "t.ray:3:13: error: unknown material 'nosuch'");
  EXPECT_EQ(error("sphere { material = 3; }"),
            "t.ray:2:21: error: expected a material block '{...}' or a material name, got number 3");
}

TEST(RayParserMaterial, BlocksStartFromTheDefault) {
  SceneDesc s = parse(
      "material = { diffuse = (0.5, 0.5, 0.5); specular = (1, 1, 1); name = base; }\n"
      "sphere { }\n"
      "sphere { material = { diffuse = (1, 0, 0); }; }\n");
  ASSERT_EQ(s.objects.size(), 2u);
  const MaterialDesc& a = materialOf(s, 0);
  expectVec(a.diffuse.value, 0.5f, 0.5f, 0.5f);
  EXPECT_EQ(a.name, "base");
  const MaterialDesc& b = materialOf(s, 1);
  expectVec(b.diffuse.value, 1, 0, 0);
  expectVec(b.specular.value, 1, 1, 1);  // inherited
  EXPECT_EQ(b.name, "");                 // the name is not inherited
  // A name as the default.
  SceneDesc t = parse("sphere { material = { name g; diffuse = (0,1,0); }; }\nmaterial = g;\nbox {}");
  EXPECT_EQ(t.objects[1].material, t.objects[0].material);
}

TEST(RayParserMaterial, GroupDefaultIsScopedToTheGroup) {
  SceneDesc s = parse(
      "material = { diffuse = (1, 0, 0); }\n"
      "{\n"
      "  sphere {}\n"
      "  material = { diffuse = (0, 1, 0); }\n"
      "  sphere {}\n"
      "  { material = { diffuse = (0, 0, 1); } sphere {} }\n"
      "  sphere {}\n"
      "}\n"
      "sphere {}\n");
  ASSERT_EQ(s.objects.size(), 5u);
  expectVec(materialOf(s, 0).diffuse.value, 1, 0, 0);
  expectVec(materialOf(s, 1).diffuse.value, 0, 1, 0);
  expectVec(materialOf(s, 2).diffuse.value, 0, 0, 1);
  expectVec(materialOf(s, 3).diffuse.value, 0, 1, 0);
  expectVec(materialOf(s, 4).diffuse.value, 1, 0, 0);
}

TEST(RayParserMaterial, UnknownAttributeStrictAndLenient) {
  EXPECT_EQ(error("sphere { material = {\n  glow = (1,1,1); }; }"),
            "t.ray:3:3: error: unknown keyword 'glow' in material");
  SceneDesc s = parseLenient("sphere { material = {\n  glow = (1,1,1);\n  diffuse = (0,1,0); }; }");
  expectVec(materialOf(s, 0).diffuse.value, 0, 1, 0);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "t.ray:3:3: warning: unknown keyword 'glow' in material (skipped)");
}

TEST(RayParserMaterial, LenientSkipsNestedValuesAndBlocks) {
  SceneDesc s = parseLenient(
      "sphere { material = {\n"
      "  fancy = { a = (1, (2, 3)); b = { c; } };\n"
      "  bare;\n"
      "  diffuse = (0, 0, 1)\n"
      "  trailing = map(\"x\") }; }\n"
      "box {}");
  ASSERT_EQ(s.objects.size(), 2u);
  expectVec(materialOf(s, 0).diffuse.value, 0, 0, 1);
  EXPECT_EQ(s.warnings.size(), 3u);
  // Unbalanced skipped values are still errors.
  ParseOptions o;
  o.lenient = true;
  EXPECT_EQ(error("sphere { foo = (1, 2 }", o), "t.ray:2:22: error: expected ')', got '}'");
}

// ---------------------------------------------------------------------------------------
// Luminosity (object lights)

TEST(RayParserLuminosity, AllFields) {
  SceneDesc s = parse(
      "square { material = {\n"
      "  diffuse = (0.8, 0.8, 0.8);\n"
      "  luminosity = {\n"
      "    colour = (1.0, 0.9, 0.7);\n"
      "    intensity = 25;\n"
      "    density = 4;\n"
      "    constant_attenuation_coeff = 0.5; linear_attenuation_coeff = 0.25; quadratic_attenuation_coeff = 2;\n"
      "  };\n"
      "}; }");
  const MaterialDesc& m = materialOf(s, 0);
  ASSERT_TRUE(m.luminosity);
  const LuminosityDesc& l = *m.luminosity;
  expectVec(l.colour.value, 1.0f, 0.9f, 0.7f);
  EXPECT_FALSE(l.colourFromDiffuse);
  EXPECT_EQ(l.intensity, 25.0f);
  EXPECT_EQ(l.density, 4.0f);
  EXPECT_EQ(l.attenConstant, 0.5f);
  EXPECT_EQ(l.attenLinear, 0.25f);
  EXPECT_EQ(l.attenQuadratic, 2.0f);
  EXPECT_EQ(l.loc.line, 4);
  EXPECT_EQ(l.loc.column, 3);
  EXPECT_FALSE(m.emissiveSet);
}

TEST(RayParserLuminosity, DefaultsTextureAndMap) {
  SceneDesc s = parse("square { material = { luminosity = { }; }; }\n"
                      "square { material = { diffuse = map(\"d.png\"); luminosity = { color = texture; }; }; }\n"
                      "square { material = { luminosity = { colour = map(\"l.png\") }; }; }");
  const LuminosityDesc& a = *materialOf(s, 0).luminosity;
  expectVec(a.colour.value, 1, 1, 1);
  EXPECT_EQ(a.intensity, 1.0f);
  EXPECT_EQ(a.density, 1.0f);
  EXPECT_EQ(a.attenConstant, 0.0f);
  EXPECT_EQ(a.attenLinear, 0.0f);
  EXPECT_EQ(a.attenQuadratic, 1.0f);
  EXPECT_TRUE(materialOf(s, 1).luminosity->colourFromDiffuse);
  EXPECT_FALSE(materialOf(s, 1).luminosity->colour.map);
  ASSERT_TRUE(materialOf(s, 2).luminosity->colour.map);
  EXPECT_EQ(materialOf(s, 2).luminosity->colour.map->path, "/base/l.png");
}

TEST(RayParserLuminosity, InvalidValues) {
  EXPECT_EQ(error("square { material = { luminosity = {\n  intensity = -2; }; }; }"),
            "t.ray:3:15: error: intensity must be >= 0, got -2");
  EXPECT_EQ(error("square { material = { luminosity = { density = -0.5; }; }; }"),
            "t.ray:2:48: error: density must be >= 0, got -0.5");
  EXPECT_EQ(error("square { material = { luminosity = { linear_attenuation_coeff = -1; }; }; }"),
            "t.ray:2:65: error: linear_attenuation_coeff must be >= 0, got -1");
  EXPECT_EQ(error("square { material = { luminosity = { power = 3; }; }; }"),
            "t.ray:2:38: error: unknown keyword 'power' in luminosity");
  EXPECT_EQ(error("square { material = { luminosity = { colour = texture(1); }; }; }"),
            "t.ray:2:54: error: expected an attribute name or '}' in luminosity, got '('");
}

TEST(RayParserLuminosity, DefaultMaterialLuminosityIsInherited) {
  SceneDesc s = parse("material = { luminosity = { intensity = 3; }; }\nsphere {}\nbox { material = { diffuse = (1,1,1); }; }");
  ASSERT_TRUE(materialOf(s, 0).luminosity);
  ASSERT_TRUE(materialOf(s, 1).luminosity);
  EXPECT_EQ(materialOf(s, 1).luminosity->intensity, 3.0f);
}

// ---------------------------------------------------------------------------------------
// Primitives

TEST(RayParserPrimitives, Kinds) {
  SceneDesc s = parse("sphere {}\nbox {}\nsquare {}\ncylinder {}\ncone {}\n");
  ASSERT_EQ(s.objects.size(), 5u);
  EXPECT_EQ(s.objects[0].kind, ShapeKind::Sphere);
  EXPECT_EQ(s.objects[1].kind, ShapeKind::Box);
  EXPECT_EQ(s.objects[2].kind, ShapeKind::Square);
  EXPECT_EQ(s.objects[3].kind, ShapeKind::Cylinder);
  EXPECT_EQ(s.objects[4].kind, ShapeKind::Cone);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(s.objects[size_t(i)].material, 0);  // the initial default
    EXPECT_EQ(s.objects[size_t(i)].loc.line, 2 + i);
    EXPECT_EQ(s.objects[size_t(i)].loc.column, 1);
    EXPECT_EQ(s.objects[size_t(i)].mesh, -1);
  }
  EXPECT_TRUE(s.objects[3].capped);
  EXPECT_EQ(s.objects[4].height, 1.0f);
  EXPECT_EQ(s.objects[4].bottomRadius, 1.0f);
  EXPECT_EQ(s.objects[4].topRadius, 0.0f);
}

TEST(RayParserPrimitives, NamesAndAttributes) {
  SceneDesc s = parse("sphere { name = \"ball\"; }\ncylinder { capped = false; name wall }\n"
                      "cone { capped = true; height = 2; bottom_radius = 0.5; top_radius = 0.2; }");
  EXPECT_EQ(s.objects[0].name, "ball");
  EXPECT_EQ(s.objects[1].name, "wall");
  EXPECT_FALSE(s.objects[1].capped);
  EXPECT_TRUE(s.objects[2].capped);
  EXPECT_EQ(s.objects[2].height, 2.0f);
  EXPECT_EQ(s.objects[2].bottomRadius, 0.5f);
  EXPECT_EQ(s.objects[2].topRadius, 0.2f);
}

TEST(RayParserPrimitives, InvalidAttributes) {
  EXPECT_EQ(error("sphere { capped = true; }"), "t.ray:2:10: error: unknown keyword 'capped' in sphere");
  EXPECT_EQ(error("cone { height = 0; }"), "t.ray:2:17: error: height must be > 0, got 0");
  EXPECT_EQ(error("cone { top_radius = -1; }"), "t.ray:2:21: error: top_radius must be >= 0, got -1");
  EXPECT_EQ(error("cone { bottom_radius = 0; }"),
            "t.ray:2:1: error: cone has bottom_radius and top_radius both 0");
  EXPECT_EQ(error("sphere ;"), "t.ray:2:8: error: expected '{' after sphere, got ';'");
}

TEST(RayParserPrimitives, UnknownObjectLenient) {
  EXPECT_EQ(error("translate(1,0,0, torus { r = 1; })"), "t.ray:2:18: error: unknown keyword 'torus'");
  SceneDesc s = parseLenient("translate(1,0,0, torus { r = 1; })\nsphere {}");
  EXPECT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.warnings.size(), 1u);
}

// ---------------------------------------------------------------------------------------
// Transforms and groups

TEST(RayParserTransforms, Translate) {
  SceneDesc s = parse("translate(1, -2, 3.5, sphere {})");
  EXPECT_EQ(s.objects[0].transform.m[0][3], 1.0);
  EXPECT_EQ(s.objects[0].transform.m[1][3], -2.0);
  EXPECT_EQ(s.objects[0].transform.m[2][3], 3.5);
  EXPECT_EQ(s.objects[0].transform.m[0][0], 1.0);
}

TEST(RayParserTransforms, ScaleOneAndThreeArguments) {
  SceneDesc s = parse("scale(2, sphere {})\nscale(1, 2, 3, box {})");
  EXPECT_EQ(s.objects[0].transform.m[0][0], 2.0);
  EXPECT_EQ(s.objects[0].transform.m[1][1], 2.0);
  EXPECT_EQ(s.objects[0].transform.m[2][2], 2.0);
  EXPECT_EQ(s.objects[1].transform.m[0][0], 1.0);
  EXPECT_EQ(s.objects[1].transform.m[1][1], 2.0);
  EXPECT_EQ(s.objects[1].transform.m[2][2], 3.0);
}

TEST(RayParserTransforms, RotateNormalisesTheAxisAndUsesRadians) {
  SceneDesc s = parse("rotate(0, 0, 5, 1.5707963267948966, sphere {})");
  Vec3 p = s.objects[0].transform.point(Vec3(1, 0, 0));
  expectVec(p, 0, 1, 0, 1e-6f);
  SceneDesc t = parse("rotate(1, 1, 1, 2.0943951023931953, sphere {})");  // 120 deg: x -> y
  expectVec(t.objects[0].transform.point(Vec3(1, 0, 0)), 0, 1, 0, 1e-6f);
}

TEST(RayParserTransforms, TransformMatrixIsRowMajor) {
  SceneDesc s = parse("transform((1,0,0,5), (0,2,0,6), (0,0,3,7), (0,0,0,1), sphere {})");
  const Mat4& m = s.objects[0].transform;
  EXPECT_EQ(m.m[0][3], 5.0);
  EXPECT_EQ(m.m[1][3], 6.0);
  EXPECT_EQ(m.m[2][3], 7.0);
  EXPECT_EQ(m.m[1][1], 2.0);
  expectVec(m.point(Vec3(1, 1, 1)), 6, 8, 10);
}

TEST(RayParserTransforms, ComposeParentTimesChild) {
  // The scale applies first, then the rotation, then the translation.
  SceneDesc s = parse("translate(1, 0, 0,\n rotate(0, 0, 1, 1.5707963267948966,\n  scale(2,\n   sphere {})))");
  Vec3 p = s.objects[0].transform.point(Vec3(1, 0, 0));
  expectVec(p, 1, 2, 0, 1e-6f);
  // Non-uniform: scale(1,3,1) then translate: (0,1,0) -> (0,3,0) -> (5,3,0)
  SceneDesc t = parse("translate(5,0,0, scale(1,3,1, box {}))");
  expectVec(t.objects[0].transform.point(Vec3(0, 1, 0)), 5, 3, 0);
  // The reverse nesting order gives a different point: (0,1,0) -> (5,1,0) -> (5,3,0)... and x*1.
  SceneDesc u = parse("scale(2,3,1, translate(5,0,0, box {}))");
  expectVec(u.objects[0].transform.point(Vec3(0, 1, 0)), 10, 3, 0);
}

TEST(RayParserTransforms, GroupsShareTheirTransform) {
  SceneDesc s = parse("translate(0, 0, 4, {\n sphere {}\n translate(1,0,0, box {})\n ;\n})\nsphere {}");
  ASSERT_EQ(s.objects.size(), 3u);
  expectVec(s.objects[0].transform.point(Vec3(0, 0, 0)), 0, 0, 4);
  expectVec(s.objects[1].transform.point(Vec3(0, 0, 0)), 1, 0, 4);
  expectVec(s.objects[2].transform.point(Vec3(0, 0, 0)), 0, 0, 0);
  // Empty groups are fine.
  EXPECT_TRUE(parse("{ }\n{ { } }\ntranslate(1,1,1, {})").objects.empty());
}

TEST(RayParserTransforms, Errors) {
  EXPECT_EQ(error("rotate(0, 0, 0, 1, sphere {})"), "t.ray:2:8: error: rotate axis must not be zero");
  EXPECT_EQ(error("scale(1, 0, 1, sphere {})"),
            "t.ray:2:10: error: scale factor must not be zero (the transform would be singular)");
  EXPECT_EQ(error("scale(0, sphere {})"),
            "t.ray:2:7: error: scale factor must not be zero (the transform would be singular)");
  EXPECT_EQ(error("transform((1,0,0,0), (0,1,0,0), (0,0,1,0), (0,0,1,1), sphere {})"),
            "t.ray:2:44: error: the last row of a transform must be (0,0,0,1)");
  EXPECT_EQ(error("transform((1,0,0,0), (1,0,0,0), (0,0,1,0), (0,0,0,1), sphere {})"),
            "t.ray:2:1: error: transform matrix is singular");
  EXPECT_EQ(error("translate(1, 2, 3)"), "t.ray:2:18: error: expected ',', got ')'");
  EXPECT_EQ(error("translate(1, 2, 3, )"), "t.ray:2:20: error: expected a primitive, transform or '{', got ')'");
  EXPECT_EQ(error("translate(1, 2, sphere {})"), "t.ray:2:17: error: expected a number, got 'sphere'");
  EXPECT_EQ(error("translate(1, 2, 3, sphere {} box {})"),
            "t.ray:2:30: error: expected ')' to close translate opened at 2:1, got 'box'");
  EXPECT_EQ(error("{ camera {} }"), "t.ray:2:3: error: expected a primitive, transform or '{', got 'camera'");
  EXPECT_EQ(error("translate(1e15, 0, 0, scale(1e15, 1e15, 1e15, translate(1e15, 0, 0, sphere {})))"),
            "t.ray:2:47: error: transform overflows (an entry of the accumulated matrix exceeds 1e30)");
}

std::string repeat(const std::string& s, int n) {
  std::string r;
  r.reserve(s.size() * size_t(n));
  for (int i = 0; i < n; ++i) r += s;
  return r;
}

TEST(RayParserNesting, DeepTranslatesHitTheLimitWithoutOverflowingTheStack) {
  std::string text = repeat("translate(0,0,0,", 100000) + "sphere {}" + repeat(")", 100000);
  // The 1001st translate (each is 16 characters) is the first one too deep.
  EXPECT_EQ(error(text),
            "t.ray:2:16001: error: nesting deeper than the limit of 1000 levels (raise it with --max-nesting)");
}

TEST(RayParserNesting, DeepGroupsHitTheLimit) {
  std::string text = repeat("{", 100000) + repeat("}", 100000);
  EXPECT_EQ(error(text),
            "t.ray:2:1001: error: nesting deeper than the limit of 1000 levels (raise it with --max-nesting)");
}

TEST(RayParserNesting, ExactlyAtTheLimitParses) {
  SceneDesc s = parse(repeat("{", 1000) + "sphere {}" + repeat("}", 1000));
  EXPECT_EQ(s.objects.size(), 1u);
  ParseOptions o;
  o.limits.maxNesting = 3;
  EXPECT_NO_THROW(parse("translate(1,0,0, { scale(2, sphere {}) })", o));
  EXPECT_EQ(error("translate(1,0,0, { scale(2, { sphere {} }) })", o),
            "t.ray:2:29: error: nesting deeper than the limit of 3 levels (raise it with --max-nesting)");
}

TEST(RayParserNesting, RaisedLimitParsesVeryDeepNestingIteratively) {
  // 100000 levels would overflow a recursive parser's stack; this one keeps an explicit stack.
  ParseOptions o;
  o.limits.maxNesting = 200000;
  SceneDesc s = parse(repeat("translate(1,0,0,", 50000) + repeat("{", 50000) + "sphere {}" + repeat("}", 50000) +
                          repeat(")", 50000),
                      o);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].transform.m[0][3], 50000.0);
}

TEST(RayParserNesting, LenientSkippingIsBoundedToo) {
  ParseOptions o;
  o.lenient = true;
  EXPECT_EQ(error("fog = " + repeat("(", 100000), o),
            "t.ray:2:1007: error: nesting deeper than the limit of 1000 levels (raise it with --max-nesting)");
}

// ---------------------------------------------------------------------------------------
// Trimesh

TEST(RayParserTrimesh, AllLists) {
  SceneDesc s = parse(
      "trimesh {\n"
      "  name = \"quad\";\n"
      "  points = ((0,0,0), (1,0,0), (1,1,0), (0,1,0));\n"
      "  faces = ((0,1,2), (0,2,3));\n"
      "  normals = ((0,0,1), (0,0,1), (0,0,1), (0,0,1));\n"
      "  texture_uv = ((0,0), (1,0), (1,1), (0,1));\n"
      "  materials = ({ diffuse = (1,0,0); }, { diffuse = (0,1,0); }, { name = v3; }, v3);\n"
      "  gennormals;\n"
      "  material = { specular = (1,1,1); };\n"
      "}");
  ASSERT_EQ(s.objects.size(), 1u);
  const ObjectDesc& o = s.objects[0];
  EXPECT_EQ(o.kind, ShapeKind::Mesh);
  EXPECT_EQ(o.name, "quad");
  ASSERT_EQ(o.mesh, 0);
  const MeshDesc& m = s.meshes[0];
  ASSERT_EQ(m.points.size(), 4u);
  expectVec(m.points[2], 1, 1, 0);
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{0, 2, 3}));
  ASSERT_EQ(m.normals.size(), 4u);
  expectVec(m.normals[3], 0, 0, 1);
  ASSERT_EQ(m.uvs.size(), 4u);
  EXPECT_EQ(m.uvs[2].x, 1.0f);
  EXPECT_EQ(m.uvs[2].y, 1.0f);
  EXPECT_TRUE(m.genNormals);
  EXPECT_TRUE(m.triangleMaterials.empty());
  ASSERT_EQ(m.vertexMaterials.size(), 4u);
  expectVec(s.materials[size_t(m.vertexMaterials[0])].diffuse.value, 1, 0, 0);
  expectVec(s.materials[size_t(m.vertexMaterials[1])].diffuse.value, 0, 1, 0);
  EXPECT_EQ(m.vertexMaterials[2], m.vertexMaterials[3]);  // by name
  EXPECT_EQ(s.materials[size_t(m.vertexMaterials[2])].name, "v3");
  expectVec(materialOf(s, 0).specular.value, 1, 1, 1);
  // Per-vertex blocks start from the default material, not from the mesh's own material.
  expectVec(s.materials[size_t(m.vertexMaterials[0])].specular.value, 0, 0, 0);
  EXPECT_EQ(s.materials.size(), 5u);  // default, 3 vertex blocks, the mesh's material
}

TEST(RayParserTrimesh, PolymeshAliasAndPolygonFans) {
  SceneDesc s = parse("polymesh { points = ((0,0,0),(1,0,0),(2,1,0),(1,2,0),(0,1,0)); faces = ((0,1,2,3,4)); }");
  const MeshDesc& m = s.meshes[0];
  ASSERT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangles[2], (std::array<int, 3>{0, 3, 4}));
  EXPECT_FALSE(m.genNormals);
}

TEST(RayParserTrimesh, TexCoordAliases) {
  for (const char* key : {"texture_uv", "texcoords", "tex_coords"}) {
    SceneDesc s = parse(std::string("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); ") + key +
                        " = ((0.25,0.5),(1,0),(0,1)); }");
    ASSERT_EQ(s.meshes[0].uvs.size(), 3u) << key;
    EXPECT_EQ(s.meshes[0].uvs[0].x, 0.25f) << key;
    EXPECT_EQ(s.meshes[0].uvs[0].y, 0.5f) << key;
  }
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2));\n texcoords = ((0,0),(1,0)); }"),
            "t.ray:3:2: error: trimesh has 3 points but 2 texcoords");
}

TEST(RayParserTrimesh, GenNormalsForms) {
  const std::string pts = "points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)) ";
  EXPECT_TRUE(parse("trimesh { " + pts + "gennormals; }").meshes[0].genNormals);
  EXPECT_TRUE(parse("trimesh { " + pts + "gennormals }").meshes[0].genNormals);
  EXPECT_TRUE(parse("trimesh { gennormals " + pts + "}").meshes[0].genNormals);
  EXPECT_TRUE(parse("trimesh { " + pts + "gennormals = true; }").meshes[0].genNormals);
  EXPECT_FALSE(parse("trimesh { " + pts + "gennormals = false; }").meshes[0].genNormals);
  EXPECT_EQ(error("trimesh { " + pts + "gennormals = 1; }"), "t.ray:2:78: error: expected true or false, got number 1");
}

TEST(RayParserTrimesh, SemicolonsAfterListsAreOptional) {
  SceneDesc s = parse("trimesh {\n points = ((0,0,0),(1,0,0),(0,1,0))\n faces = ((0,1,2))\n"
                      " normals = ((0,0,1),(0,0,1),(0,0,1))\n}");
  EXPECT_EQ(s.meshes[0].triangles.size(), 1u);
  EXPECT_EQ(s.meshes[0].normals.size(), 3u);
}

TEST(RayParserTrimesh, FaceErrors) {
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0));\n  faces = ((0,1,2), (0, 1)); }"),
            "t.ray:3:21: error: a face needs at least 3 indices, got 2");
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0));\n  faces = ((0,1,3)); }"),
            "t.ray:3:17: error: face index 3 is out of range (the mesh has 3 points)");
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0));\n  faces = ((0,-1,2)); }"),
            "t.ray:3:15: error: face index -1 is out of range (the mesh has 3 points)");
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0));\n  faces = ((0,1.5,2)); }"),
            "t.ray:3:15: error: face index 1.5 is not an integer");
  // Faces before points: checked at the '}', still at the index's own position.
  EXPECT_EQ(error("trimesh {\n  faces = ((0,1,2), (2,1,7));\n  points = ((0,0,0),(1,0,0),(0,1,0)); }"),
            "t.ray:3:26: error: face index 7 is out of range (the mesh has 3 points)");
  SceneDesc s = parse("trimesh { faces = ((2,1,0)); points = ((0,0,0),(1,0,0),(0,1,0)); }");
  EXPECT_EQ(s.meshes[0].triangles[0], (std::array<int, 3>{2, 1, 0}));
}

TEST(RayParserTrimesh, CountMismatchAndMissingLists) {
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2));\n  normals = ((0,0,1)); }"),
            "t.ray:3:3: error: trimesh has 3 points but 1 normals");
  EXPECT_EQ(error("polymesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2));\n  materials = ({}, {}); }"),
            "t.ray:3:3: error: polymesh has 3 points but 2 materials");
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); }"), "t.ray:2:1: error: trimesh needs points and faces");
  EXPECT_EQ(error("trimesh { }"), "t.ray:2:1: error: trimesh needs points and faces");
  EXPECT_EQ(error("trimesh { points = ((0,0,0)); points = ((0,0,0)); }"),
            "t.ray:2:31: error: 'points' is given twice in trimesh");
  EXPECT_EQ(error("trimesh { points = ((0,0)); }"), "t.ray:2:21: error: expected 3 numbers, got 2");
  EXPECT_EQ(error("trimesh { points = (0,0,0); }"), "t.ray:2:21: error: expected '(', got number 0");
}

TEST(RayParserTrimesh, UnknownFieldLenient) {
  const std::string body = "trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2));\n  glow = (1,1,1); }";
  EXPECT_EQ(error(body), "t.ray:3:3: error: unknown keyword 'glow' in trimesh");
  SceneDesc s = parseLenient(body);
  EXPECT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.warnings.size(), 1u);
}

TEST(RayParserTrimesh, TriangleAndVertexLimits) {
  ParseOptions o;
  o.limits.maxTriangles = 3;
  // One mesh of 2 triangles then another whose second triangle is the 4th in the scene.
  std::string body = "trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2),(0,1,2)); }\n"
                     "trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2),(0,1,2)); }";
  EXPECT_EQ(error(body, o), "t.ray:3:64: error: more triangles than the limit of 3 (raise it with --max-triangles)");
  // A polygon counts its fan triangles.
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0),(1,1,0),(2,2,0)); faces = ((0,1,2,3,4,0)); }", o),
            "t.ray:2:72: error: more triangles than the limit of 3 (raise it with --max-triangles)");
  ParseOptions v;
  v.limits.maxVertices = 4;
  EXPECT_EQ(error("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); }\n"
                  "trimesh { points = ((0,0,0),(1,0,0)); faces = ((0,1,2)); }",
                  v),
            "t.ray:3:29: error: more vertices than the limit of 4 (raise it with --max-triangles)");
  // Area lights count too.
  ParseOptions a;
  a.limits.maxTriangles = 1;
  EXPECT_EQ(error("area_light { u = (1,0,0); v = (0,1,0); }", a),
            "t.ray:2:1: error: more triangles than the limit of 1 (raise it with --max-triangles)");
}

TEST(RayParserTrimesh, Transformed) {
  SceneDesc s = parse("translate(0,0,1, scale(2, trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); }))");
  // Points stay in the mesh's local frame; the object carries the transform.
  expectVec(s.meshes[0].points[1], 1, 0, 0);
  expectVec(s.objects[0].transform.point(s.meshes[0].points[1]), 2, 0, 1);
}

// ---------------------------------------------------------------------------------------
// obj_mesh

TEST(RayParserObjMesh, NeedsAFile) {
  EXPECT_EQ(error("obj_mesh { name = x; }"), "t.ray:2:1: error: obj_mesh needs a file");
  EXPECT_EQ(error("obj_mesh { file = \"\"; }"), "t.ray:2:19: error: empty file name");
  EXPECT_EQ(error("obj_mesh { file = 3; }"), "t.ray:2:19: error: expected a file name, got number 3");
  EXPECT_EQ(error("obj_mesh { shape = 3; }"), "t.ray:2:12: error: unknown keyword 'shape' in obj_mesh");
}

TEST(RayParserObjMesh, LoaderErrorsPointAtTheObjMesh) {
  try {
    parse("\n  obj_mesh { file = \"does-not-exist.obj\"; }");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.loc().file, "t.ray");
    EXPECT_EQ(e.loc().line, 3);
    EXPECT_EQ(e.loc().column, 3);
  }
}

TEST(RayParserObjMesh, LoadsARealObjWhenTheLoaderIsAvailable) {
  std::string dir = lc::testing::dataPath("models");
  std::string text = std::string(kHeader) +
                     "translate(1,0,0, obj_mesh { file = \"cube.obj\"; name = cube; })\n"
                     "obj_mesh { file = \"cube.obj\"; material = { diffuse = (0.25, 0.5, 1); }; }\n";
  SceneDesc s;
  try {
    s = parseRayString(text, "t.ray", dir, {});
  } catch (const Error& e) {
    if (std::string(e.what()).find("not supported yet") != std::string::npos)
      GTEST_SKIP() << "OBJ loader not implemented yet";
    throw;
  }
  ASSERT_EQ(s.objects.size(), 2u);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.objects[0].kind, ShapeKind::Mesh);
  EXPECT_EQ(s.objects[0].name, "cube");
  EXPECT_EQ(s.objects[0].transform.m[0][3], 1.0);
  EXPECT_FALSE(s.meshes[0].triangles.empty());
  for (int id : s.meshes[0].triangleMaterials) {
    EXPECT_GT(id, 0);
    EXPECT_LT(size_t(id), s.materials.size());
  }
  EXPECT_TRUE(s.meshes[1].triangleMaterials.empty());  // the explicit material overrides the MTL
  expectVec(materialOf(s, 1).diffuse.value, 0.25f, 0.5f, 1);
}

// `emission` on an obj_mesh (COMP4411): one emissive copy of its material for the whole mesh.
TEST(RayParserObjMesh, EmissionMakesTheMeshALight) {
  std::string dir = lc::testing::dataPath("models");
  std::string text = std::string(kHeader) +
                     "obj_mesh { file = \"cube.obj\"; emission = (1, 2, 3); }\n"
                     "obj_mesh { file = \"cube.obj\"; material = { diffuse = (0.25, 0.5, 1); }; emission = (4, 4, 4); }\n";
  SceneDesc s = parseRayString(text, "t.ray", dir, {});
  ASSERT_EQ(s.objects.size(), 2u);
  for (int i = 0; i < 2; ++i) EXPECT_TRUE(s.meshes[size_t(i)].triangleMaterials.empty()) << i;
  const MaterialDesc& a = materialOf(s, 0);
  ASSERT_TRUE(a.luminosity);
  EXPECT_TRUE(a.luminosity->perArea);
  expectVec(a.emissive.value, 1, 2, 3);
  const MaterialDesc& b = materialOf(s, 1);
  ASSERT_TRUE(b.luminosity);
  expectVec(b.emissive.value, 4, 4, 4);
  expectVec(b.diffuse.value, 0.25f, 0.5f, 1);
  EXPECT_EQ(error("obj_mesh { file = \"x.obj\"; emission = (-1, 0, 0); }").find("emission components must be finite and >= 0") !=
                std::string::npos,
            true);
}

TEST(RayParserObjMesh, MergeOffsetsTriangleMaterials) {
  SceneDesc s;
  s.materials.resize(3);
  ObjData obj;
  obj.mesh.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  obj.mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  obj.mesh.triangleMaterials = {1, 0};
  obj.materials.resize(2);
  obj.materials[0].name = "a";
  obj.materials[1].name = "b";
  obj.warnings = {"w1"};
  ObjectDesc o;
  o.name = "m";
  o.transform = Mat4::translate(1, 2, 3);
  detail::appendObjMesh(s, ObjData(obj), o, std::nullopt, 2);
  ASSERT_EQ(s.materials.size(), 5u);
  EXPECT_EQ(s.materials[3].name, "a");
  EXPECT_EQ(s.materials[4].name, "b");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangleMaterials, (std::vector<int>{4, 3}));
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].kind, ShapeKind::Mesh);
  EXPECT_EQ(s.objects[0].mesh, 0);
  EXPECT_EQ(s.objects[0].material, 3);
  EXPECT_EQ(s.objects[0].name, "m");
  EXPECT_EQ(s.objects[0].transform.m[1][3], 2.0);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{"w1"}));

  // An explicit material overrides: no per-triangle materials, no MTL materials appended.
  detail::appendObjMesh(s, ObjData(obj), o, 1, 2);
  EXPECT_EQ(s.materials.size(), 5u);
  EXPECT_TRUE(s.meshes[1].triangleMaterials.empty());
  EXPECT_EQ(s.objects[1].material, 1);
  EXPECT_EQ(s.objects[1].mesh, 1);

  // An OBJ without materials uses the default.
  ObjData bare = obj;
  bare.materials.clear();
  bare.mesh.triangleMaterials.clear();
  detail::appendObjMesh(s, std::move(bare), o, std::nullopt, 2);
  EXPECT_EQ(s.objects[2].material, 2);

  ObjData bad = obj;
  bad.mesh.triangleMaterials = {0, 5};
  EXPECT_THROW(detail::appendObjMesh(s, std::move(bad), o, std::nullopt, 2), Error);
}

// ---------------------------------------------------------------------------------------
// Lights

TEST(RayParserLights, AmbientLightsAddUp) {
  SceneDesc s = parse("ambient_light { colour = (0.1, 0.2, 0.3); }\nambient_light { color = (0.1, 0, 0); }");
  expectVec(s.ambient, 0.2f, 0.2f, 0.3f, 1e-7f);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(error("ambient_light { position = (0,0,0); }"),
            "t.ray:2:17: error: unknown keyword 'position' in ambient_light");
}

TEST(RayParserLights, PointLight) {
  SceneDesc s = parse("point_light {\n position = (1, 2, 3);\n colour = (0.5, 0.25, 1);\n"
                      " constant_attenuation_coeff = 0.25; linear_attenuation_coeff = 0.003372407;\n"
                      " quadratic_attenuation_coeff = 0.000045492; }\npoint_light { }");
  ASSERT_EQ(s.lights.size(), 2u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.kind, LightKind::Point);
  expectVec(l.position, 1, 2, 3);
  expectVec(l.colour, 0.5f, 0.25f, 1);
  EXPECT_EQ(l.attenConstant, 0.25f);
  EXPECT_EQ(l.attenLinear, 0.003372407f);
  EXPECT_EQ(l.attenQuadratic, 0.000045492f);
  EXPECT_EQ(l.loc.line, 2);
  const LightDesc& d = s.lights[1];
  expectVec(d.colour, 1, 1, 1);
  EXPECT_EQ(d.attenConstant, 0.0f);
  EXPECT_EQ(d.attenLinear, 0.0f);
  EXPECT_EQ(d.attenQuadratic, 1.0f);
  EXPECT_EQ(error("point_light { quadratic_attenuation_coeff = -0.1; }"),
            "t.ray:2:45: error: quadratic_attenuation_coeff must be >= 0, got -0.1");
  EXPECT_EQ(error("point_light { direction = (0,0,1); }"),
            "t.ray:2:15: error: unknown keyword 'direction' in point_light");
}

TEST(RayParserLights, DirectionalLight) {
  SceneDesc s = parse("directional_light { direction = (0, -1, 0); color = (0.2, 0.2, 0.2); }");
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].kind, LightKind::Directional);
  expectVec(s.lights[0].direction, 0, -1, 0);
  expectVec(s.lights[0].colour, 0.2f, 0.2f, 0.2f);
  EXPECT_EQ(error("directional_light { direction = (0, 0, 0); }"),
            "t.ray:2:33: error: direction must not be zero");
  EXPECT_EQ(error("directional_light { position = (0, 0, 0); }"),
            "t.ray:2:21: error: unknown keyword 'position' in directional_light");
  EXPECT_EQ(error("directional_light { constant_attenuation_coeff = 1; }"),
            "t.ray:2:21: error: unknown keyword 'constant_attenuation_coeff' in directional_light");
}

TEST(RayParserLights, SpotLightSeedForm) {
  SceneDesc s = parse("spot_light { position = (0, 3, 0); direction = (0, -1, 0); colour = (1, 1, 0.5);\n"
                      " exponent = 8; cutoff = 30; constant_attenuation_coeff = 1; linear_attenuation_coeff = 0.5;"
                      " quadratic_attenuation_coeff = 0; }");
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.kind, LightKind::Spot);
  expectVec(l.position, 0, 3, 0);
  expectVec(l.direction, 0, -1, 0);
  expectVec(l.colour, 1, 1, 0.5f);
  EXPECT_EQ(l.exponent, 8.0f);
  EXPECT_EQ(l.cutoffDegrees, 30.0f);
  EXPECT_EQ(l.attenConstant, 1.0f);
  EXPECT_EQ(l.attenLinear, 0.5f);
  EXPECT_EQ(l.attenQuadratic, 0.0f);
  EXPECT_FALSE(l.coneAngleDegrees);
  EXPECT_TRUE(std::isinf(l.cutoffDistance));
  // Defaults
  SceneDesc d = parse("spot_light { }");
  EXPECT_EQ(d.lights[0].exponent, 0.0f);
  EXPECT_EQ(d.lights[0].cutoffDegrees, 90.0f);
  EXPECT_EQ(d.lights[0].penumbraDegrees, 0.0f);
}

TEST(RayParserLights, SpotLightUwAndBlenderForms) {
  SceneDesc s = parse("spot_light { cutoff_distance = 500; penumbra = 10; cone_angle = 30;\n"
                      " position = (0, 3, 6); target = (0, 0, 0); color = (1, 0, 0); }\n"
                      "spot_light { size = 60; blend = 0.25; }\n"
                      "spot_light { blend = 0.5; cone_angle = 20; }");
  const LightDesc& a = s.lights[0];
  expectVec(a.direction, 0, -3, -6);  // target - position
  EXPECT_EQ(a.cutoffDistance, 500.0f);
  EXPECT_EQ(a.penumbraDegrees, 10.0f);
  ASSERT_TRUE(a.coneAngleDegrees);
  EXPECT_EQ(*a.coneAngleDegrees, 30.0f);
  const LightDesc& b = s.lights[1];
  EXPECT_EQ(*b.coneAngleDegrees, 30.0f);
  EXPECT_EQ(b.penumbraDegrees, 7.5f);
  EXPECT_EQ(*s.lights[2].coneAngleDegrees, 20.0f);
  EXPECT_EQ(s.lights[2].penumbraDegrees, 10.0f);
  // The later of direction/target wins.
  SceneDesc t = parse("spot_light { target = (0,0,0); direction = (1,0,0); position = (0,5,0); }");
  expectVec(t.lights[0].direction, 1, 0, 0);
}

TEST(RayParserLights, SpotLightErrors) {
  EXPECT_EQ(error("spot_light { position = (1,1,1);\n target = (1,1,1); }"),
            "t.ray:3:11: error: target must differ from the light position");
  EXPECT_EQ(error("spot_light { cutoff = 0; }"), "t.ray:2:23: error: cutoff must be in (0, 180] degrees, got 0");
  EXPECT_EQ(error("spot_light { cone_angle = 200; }"),
            "t.ray:2:27: error: cone_angle must be in (0, 180] degrees, got 200");
  EXPECT_EQ(error("spot_light { blend = 1.5; size = 10; }"), "t.ray:2:22: error: blend must be in [0, 1], got 1.5");
  EXPECT_EQ(error("spot_light { blend = 0.5; }"), "t.ray:2:22: error: blend needs size or cone_angle");
  EXPECT_EQ(error("spot_light { size = 0; }"), "t.ray:2:21: error: size must be in (0, 360] degrees, got 0");
  EXPECT_EQ(error("spot_light { cutoff_distance = 0; }"), "t.ray:2:32: error: cutoff_distance must be > 0, got 0");
  EXPECT_EQ(error("spot_light { exponent = -1; }"), "t.ray:2:25: error: exponent must be >= 0, got -1");
  EXPECT_EQ(error("spot_light { linear_attenuation_coeff = -1; }"),
            "t.ray:2:41: error: linear_attenuation_coeff must be >= 0, got -1");
}

TEST(RayParserLights, LightLimit) {
  ParseOptions o;
  o.limits.maxLights = 2;
  EXPECT_EQ(error("point_light {}\nspot_light {}\ndirectional_light {}", o),
            "t.ray:4:1: error: more lights than the limit of 2 (raise it with --max-lights)");
}

TEST(RayParserLights, AreaLightBecomesAnEmissiveMesh) {
  SceneDesc s = parse(
      "material = { specular = (0.5, 0.5, 0.5); diffuse = (0.9, 0.9, 0.9); }\n"
      "area_light {\n"
      "  position = (1, 0, -4);\n"
      "  u = (-1, 0, 0);\n"
      "  v = (0, 2, 0);\n"
      "  color = (1.0, 0.5, 0.25);\n"
      "}");
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.objects.size(), 1u);
  const ObjectDesc& o = s.objects[0];
  EXPECT_EQ(o.kind, ShapeKind::Mesh);
  EXPECT_EQ(o.loc.line, 3);
  const MeshDesc& m = s.meshes.at(size_t(o.mesh));
  ASSERT_EQ(m.points.size(), 4u);
  expectVec(m.points[0], 1, 0, -4);
  expectVec(m.points[1], 0, 0, -4);
  expectVec(m.points[2], 0, 2, -4);
  expectVec(m.points[3], 1, 2, -4);
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{0, 2, 3}));
  const MaterialDesc& mat = materialOf(s, 0);
  ASSERT_TRUE(mat.luminosity);
  expectVec(mat.luminosity->colour.value, 1, 0.5f, 0.25f);
  EXPECT_EQ(mat.luminosity->intensity, 1.0f);
  EXPECT_EQ(mat.luminosity->density, 1.0f);
  expectVec(mat.diffuse.value, 0, 0, 0);
  expectVec(mat.specular.value, 0.5f, 0.5f, 0.5f);  // the rest comes from the default
  EXPECT_FALSE(mat.emissiveSet);
  expectVec(o.transform.point(Vec3(1, 2, 3)), 1, 2, 3);  // world space
}

TEST(RayParserLights, AreaLightErrors) {
  EXPECT_EQ(error("area_light { u = (1,0,0); }"), "t.ray:2:1: error: area_light needs both u and v");
  EXPECT_EQ(error("\narea_light { u = (1,0,0); v = (-2,0,0); }"),
            "t.ray:3:1: error: area_light has zero area (u and v are parallel or zero)");
  EXPECT_EQ(error("area_light { u = (1,0,0); v = (0,0,0); }"),
            "t.ray:2:1: error: area_light has zero area (u and v are parallel or zero)");
  EXPECT_EQ(error("area_light { u = (1,0,0); v = (0,1,0); intensity = 3; }"),
            "t.ray:2:40: error: unknown keyword 'intensity' in area_light");
}

// ---------------------------------------------------------------------------------------
// instant_radiosity

TEST(RayParserInstantRadiosity, AllFields) {
  SceneDesc s = parse("instant_radiosity { vpls = 10000; bounces = 2; normalize = \"object\"; clamp = 0.05;"
                      " seed = 18446744073709551615; }");
  ASSERT_TRUE(s.instantRadiosity);
  const InstantRadiosityDesc& ir = *s.instantRadiosity;
  EXPECT_EQ(*ir.vpls, 10000);
  EXPECT_EQ(*ir.bounces, 2);
  EXPECT_EQ(*ir.normalize, VplNormalize::Object);
  EXPECT_EQ(*ir.clamp, 0.05f);
  EXPECT_EQ(*ir.seed, 18446744073709551615ull);
  EXPECT_EQ(ir.loc.line, 2);
  SceneDesc t = parse("instant_radiosity { normalize = power; }\ninstant_radiosity { vpls = 1e3; }");
  EXPECT_EQ(*t.instantRadiosity->normalize, VplNormalize::Power);
  EXPECT_EQ(*t.instantRadiosity->vpls, 1000);
  EXPECT_FALSE(t.instantRadiosity->bounces);
}

TEST(RayParserInstantRadiosity, Validation) {
  EXPECT_EQ(error("instant_radiosity { vpls = -1; }"), "t.ray:2:28: error: vpls must be >= 0, got -1");
  EXPECT_EQ(error("instant_radiosity { vpls = 1.5; }"),
            "t.ray:2:28: error: expected an integer for vpls, got number 1.5");
  EXPECT_EQ(error("instant_radiosity { bounces = -2; }"), "t.ray:2:31: error: bounces must be >= 0, got -2");
  EXPECT_EQ(error("instant_radiosity { clamp = -0.5; }"), "t.ray:2:29: error: clamp must be >= 0, got -0.5");
  EXPECT_EQ(error("instant_radiosity { normalize = \"area\"; }"),
            "t.ray:2:33: error: expected \"power\" or \"object\" for normalize, got string \"area\"");
  EXPECT_EQ(error("instant_radiosity { seed = 18446744073709551616; }"),
            "t.ray:2:28: error: seed 18446744073709551616 is too large");
  ParseOptions o;
  o.limits.maxVpls = 100;
  EXPECT_EQ(error("instant_radiosity { vpls = 101; }", o),
            "t.ray:2:28: error: vpls 101 is more than the limit of 100 (raise it with --max-vpls)");
  EXPECT_EQ(error("instant_radiosity { photons = 3; }"),
            "t.ray:2:21: error: unknown keyword 'photons' in instant_radiosity");
}

// ---------------------------------------------------------------------------------------
// Files

TEST(RayParserFiles, MissingFileAndSizeLimit) {
  EXPECT_THROW(parseRayFile("/nonexistent/dir/x.ray"), Error);
  lc::testing::TempDir dir;
  std::string path = dir.file("s.ray");
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_TRUE(f);
    std::fputs("SBT-raytracer 1.0\nsphere { material = { diffuse = map(\"t.bmp\"); }; }\n", f);
    std::fclose(f);
  }
  SceneDesc s = parseRayFile(path);
  EXPECT_EQ(s.path, path);
  EXPECT_EQ(materialOf(s, 0).diffuse.map->path, dir.path() + "/t.bmp");
  EXPECT_EQ(materialOf(s, 0).diffuse.map->loc.file, path);
  ParseOptions o;
  o.limits.maxFileBytes = 10;
  EXPECT_THROW(parseRayFile(path, o), Error);
}

// The example at the end of docs/SCENE_FORMAT.md parses to what it describes.
TEST(RayParserFiles, DocumentationExampleParses) {
  std::string doc = lc::readFile(lc::testing::sourceDir() + "/docs/SCENE_FORMAT.md");
  size_t at = doc.find("## Example");
  ASSERT_NE(at, std::string::npos);
  size_t begin = doc.find("```\n", at);
  ASSERT_NE(begin, std::string::npos);
  begin += 4;
  size_t end = doc.find("```", begin);
  ASSERT_NE(end, std::string::npos);
  SceneDesc s = parseRayString(doc.substr(begin, end - begin), "doc.ray", "", {});
  EXPECT_TRUE(s.hasCamera);
  EXPECT_EQ(s.lights.size(), 1u);
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(materialOf(s, 0).name, "white");
  EXPECT_TRUE(materialOf(s, 2).luminosity);
  expectVec(s.objects[2].transform.vector(Vec3(0, 0, 1)), 0, -0.5f, 0, 1e-4f);  // facing down
}

// Every public scene parses strictly, with no warnings (the COMP4411 Cornell box's `emission`
// included: see RayParserEmission).
TEST(RayParserPublicScenes, AllParse) {
  namespace fs = std::filesystem;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(lc::testing::dataPath("public-scenes"))) {
    if (entry.path().extension() != ".ray") continue;
    ++count;
    const std::string path = entry.path().string();
    const std::string name = entry.path().filename().string();
    SceneDesc s;
    EXPECT_NO_THROW(s = parseRayFile(path)) << name;
    EXPECT_TRUE(s.warnings.empty()) << name;
    EXPECT_TRUE(s.hasCamera) << name;
    EXPECT_FALSE(s.objects.empty()) << name;
  }
  EXPECT_GE(count, 13);
}

TEST(RayParserPublicScenes, CornellBoxEmission) {
  SceneDesc s = parseRayFile(lc::testing::dataPath("public-scenes/COMP4411-Team__Trace__simpleSamples_bonus_cornell_box.ray"));
  ASSERT_EQ(s.objects.size(), 6u);
  EXPECT_EQ(s.objects[0].name, "light");
  const MaterialDesc& m = materialOf(s, 0);
  expectVec(m.diffuse.value, 0.65f, 0.65f, 0.65f);
  expectVec(m.emissive.value, 478.348f, 385.664f, 310.808f);
  ASSERT_TRUE(m.luminosity);
  EXPECT_TRUE(m.luminosity->perArea);
  expectVec(m.luminosity->colour.value, 478.348f, 385.664f, 310.808f);
  EXPECT_EQ(m.luminosity->loc.line, 17);
  for (size_t i = 1; i < 6; ++i) EXPECT_FALSE(materialOf(s, i).luminosity) << i;
}

TEST(RayParserPublicScenes, ConcreteContents) {
  auto load = [](const std::string& n) { return parseRayFile(lc::testing::dataPath("public-scenes/" + n)); };

  SceneDesc cube = load("COMP4411-Team__Trace__simpleSamples_cube.ray");
  ASSERT_EQ(cube.objects.size(), 1u);
  EXPECT_EQ(cube.meshes[0].points.size(), 8u);
  EXPECT_EQ(cube.meshes[0].triangles.size(), 12u);
  ASSERT_EQ(cube.lights.size(), 1u);
  expectVec(cube.lights[0].position, 1, 1, -3);
  expectVec(materialOf(cube, 0).diffuse.value, 0.1f, 0.1f, 1.0f);
  // rotate(1,1,1,1, scale(2, translate(-0.5,-0.5,-0.5, ...))): the cube's centre stays at the origin.
  expectVec(cube.objects[0].transform.point(Vec3(0.5f, 0.5f, 0.5f)), 0, 0, 0, 1e-6f);
  EXPECT_NEAR(length(cube.objects[0].transform.vector(Vec3(1, 0, 0))), 2.0f, 1e-6f);

  SceneDesc spot = load("COMP4411-Team__Trace__simpleSamples_bonus_spotlight.ray");
  ASSERT_EQ(spot.lights.size(), 3u);
  EXPECT_EQ(spot.lights[0].kind, LightKind::Spot);
  EXPECT_EQ(spot.lights[0].cutoffDistance, 500.0f);
  EXPECT_EQ(*spot.lights[2].coneAngleDegrees, 50.0f);
  EXPECT_EQ(spot.lights[2].penumbraDegrees, 40.0f);
  expectVec(spot.lights[1].direction, 0, 3, -6);
  expectVec(spot.camera.viewDir, -1, 0, -0.3f);

  SceneDesc soft = load("COMP4411-Team__Trace__simpleSamples_bonus_soft_shadow.ray");
  ASSERT_EQ(soft.objects.size(), 4u);  // 2 area lights + 2 boxes
  EXPECT_TRUE(materialOf(soft, 0).luminosity);
  EXPECT_TRUE(materialOf(soft, 1).luminosity);
  EXPECT_FALSE(materialOf(soft, 2).luminosity);
  expectVec(soft.meshes[size_t(soft.objects[1].mesh)].points[2], 2.5f, 1, -2.5f);

  SceneDesc cone = load("OccamsRazer__cs384g__scenes_cone.ray");
  ASSERT_EQ(cone.objects.size(), 1u);
  EXPECT_EQ(cone.objects[0].kind, ShapeKind::Cone);
  EXPECT_FALSE(cone.objects[0].capped);
  EXPECT_EQ(cone.objects[0].height, 2.0f);
  EXPECT_EQ(cone.objects[0].bottomRadius, 0.5f);
  EXPECT_EQ(cone.objects[0].topRadius, 0.2f);
  EXPECT_EQ(materialOf(cone, 0).shininess.value, 76.8f);
  EXPECT_EQ(cone.lights.size(), 2u);

  SceneDesc poly = load("OccamsRazer__cs384g__scenes_polymesh_z-polytest.ray");
  const MeshDesc& pm = poly.meshes[0];
  EXPECT_EQ(pm.points.size(), 8u);
  EXPECT_EQ(pm.triangles.size(), 12u);  // six quads
  EXPECT_EQ(pm.triangles[0], (std::array<int, 3>{2, 3, 7}));
  EXPECT_EQ(pm.triangles[1], (std::array<int, 3>{2, 7, 6}));
  ASSERT_EQ(pm.vertexMaterials.size(), 8u);
  expectVec(poly.materials[size_t(pm.vertexMaterials[6])].diffuse.value, 0.4f, 0.3f, 0.3f);
  EXPECT_EQ(poly.lights[0].attenLinear, 0.003372407f);

  SceneDesc simple = load("OccamsRazer__cs384g__scenes_polymesh_simple.ray");
  ASSERT_EQ(simple.objects.size(), 2u);
  EXPECT_EQ(simple.camera.fovDegrees, 45.0f);
  EXPECT_EQ(simple.objects[0].name, "");
  EXPECT_EQ(simple.objects[1].kind, ShapeKind::Sphere);
  EXPECT_NEAR(simple.objects[1].transform.m[0][3], -0.974054, 1e-12);
  EXPECT_TRUE(materialOf(simple, 0).emissiveSet);

  SceneDesc tex = load("OccamsRazer__cs384g__scenes_simple_texture_map.ray");
  ASSERT_TRUE(materialOf(tex, 0).diffuse.map);
  EXPECT_TRUE(std::filesystem::exists(materialOf(tex, 0).diffuse.map->path));
  EXPECT_EQ(std::filesystem::path(materialOf(tex, 0).diffuse.map->path).filename(), "checkerboard.bmp");
  expectVec(tex.camera.upDir, 0, 0, 1);

  SceneDesc turtle = load("OccamsRazer__cs384g__scenes_polymesh_turtle.ray");
  EXPECT_EQ(turtle.lights.size(), 3u);
  int cones = 0, meshes = 0;
  for (const ObjectDesc& o : turtle.objects) {
    cones += o.kind == ShapeKind::Cone;
    meshes += o.kind == ShapeKind::Mesh;
  }
  EXPECT_EQ(cones, 11);
  EXPECT_EQ(meshes, 60);
  // The top-level default (specular 1, shininess 89.6) shows through every block.
  expectVec(materialOf(turtle, 0).specular.value, 1, 1, 1);
  EXPECT_EQ(materialOf(turtle, 0).shininess.value, 89.6f);

  SceneDesc atten = load("OccamsRazer__cs384g__scenes_simple_box_dist_atten.ray");
  EXPECT_EQ(atten.lights[0].attenConstant, 0.2f);
  EXPECT_EQ(atten.lights[0].attenLinear, 0.3f);
  EXPECT_EQ(atten.lights[0].attenQuadratic, 0.0f);

  SceneDesc emis = load("OccamsRazer__cs384g__scenes_simple_cyl_emissive.ray");
  EXPECT_TRUE(emis.lights.empty());
  expectVec(materialOf(emis, 0).emissive.value, 0.5f, 0, 0);

  SceneDesc refr = load("OccamsRazer__cs384g__scenes_simple_sphere_refract.ray");
  EXPECT_EQ(materialOf(refr, 0).index.value, 1.5f);
  EXPECT_EQ(refr.objects.size(), 3u);

  SceneDesc easy = load("OccamsRazer__cs384g__scenes_polymesh_easy3.ray");
  EXPECT_EQ(easy.lights.size(), 3u);
}

}  // namespace
}  // namespace lc::io

namespace lc::io {
namespace {

TEST(RayParserEmission, ObjectMaterialAndSphereLight) {
  SceneDesc s = parse(
      "material = { name = grey; diffuse = (0.3, 0.3, 0.3); }\n"
      "trimesh { material = grey; emission = (1, 2, 3); points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); }\n"
      "sphere { emission = (4, 4, 4); material = grey; }\n"
      "box { material = { emission = (5, 0, 0); diffuse = (0.1, 0.2, 0.3); }; }\n"
      "translate(1, 2, 3, sphere_light { emission = (7, 8, 9); })\n"
      "sphere_light { emission = (1, 1, 1); radius = 2; name = bulb; }\n"
      "sphere { material = grey; }\n",
      [] {
        ParseOptions o;
        o.emissionDensity = 3;
        return o;
      }());
  ASSERT_EQ(s.objects.size(), 6u);
  // Object-level emission: a copy of the object's material, unnamed, its diffuse kept.
  const MaterialDesc& t = materialOf(s, 0);
  EXPECT_EQ(t.name, "");
  expectVec(t.diffuse.value, 0.3f, 0.3f, 0.3f);
  expectVec(t.emissive.value, 1, 2, 3);
  EXPECT_TRUE(t.emissiveSet);
  ASSERT_TRUE(t.luminosity);
  EXPECT_TRUE(t.luminosity->perArea);
  EXPECT_FLOAT_EQ(t.luminosity->intensity, float(1 / 3.14159265358979323846));  // A Le / pi in all
  EXPECT_EQ(t.luminosity->density, 3);
  expectVec(t.luminosity->colour.value, 1, 2, 3);
  expectVec(materialOf(s, 1).luminosity->colour.value, 4, 4, 4);  // emission before material
  EXPECT_FALSE(materialOf(s, 5).luminosity);                      // "grey" itself is untouched
  const MaterialDesc& b = materialOf(s, 2);
  expectVec(b.diffuse.value, 0.1f, 0.2f, 0.3f);
  expectVec(b.luminosity->colour.value, 5, 0, 0);
  // sphere_light: a unit sphere under the transform, black but for its emission.
  EXPECT_EQ(s.objects[3].kind, ShapeKind::Sphere);
  expectVec(s.objects[3].transform.point(Vec3(0, 0, 0)), 1, 2, 3);
  const MaterialDesc& l = materialOf(s, 3);
  expectVec(l.diffuse.value, 0, 0, 0);
  expectVec(l.emissive.value, 7, 8, 9);
  EXPECT_TRUE(l.luminosity && l.luminosity->perArea);
  EXPECT_EQ(s.objects[4].name, "bulb");
  expectVec(s.objects[4].transform.vector(Vec3(1, 0, 0)), 2, 0, 0);
  // emission = (0,0,0) removes a luminosity.
  SceneDesc z = parse("sphere { material = { luminosity = { intensity = 2; }; emission = (0, 0, 0); }; }");
  EXPECT_FALSE(materialOf(z, 0).luminosity);
}

TEST(RayParserEmission, Errors) {
  EXPECT_EQ(error("sphere { emission = (1, -1, 0); }"),
            "t.ray:2:21: error: emission components must be finite and >= 0");
  EXPECT_EQ(error("sphere_light { }"), "t.ray:2:1: error: sphere_light needs emission = (r, g, b)");
  EXPECT_EQ(error("sphere_light { emission = (1,1,1); radius = 0; }"),
            "t.ray:2:45: error: radius must be > 0, got 0");
  EXPECT_EQ(error("sphere_light { emission = (1,1,1); material = { }; }"),
            "t.ray:2:36: error: unknown keyword 'material' in sphere_light");
}

TEST(RayParserPbr, AlbedoAndIgnoredKeys) {
  SceneDesc s = parse(
      "sphere { material = { type = \"microfacet\"; albedo = (0.2, 0.4, 0.6); metallic = 0.5;\n"
      "  roughness = 0.3; }; }\n"
      "sphere { material = { albedo = (0.9, 0.9, 0.9); diffuse = (0.1, 0.1, 0.1); roughness = 0.1;\n"
      "  translucency = 0.2; type = \"fresnel\"; }; }\n");
  expectVec(materialOf(s, 0).diffuse.value, 0.2f, 0.4f, 0.6f);
  expectVec(materialOf(s, 1).diffuse.value, 0.1f, 0.1f, 0.1f);  // diffuse wins over albedo
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "t.ray:2:23: warning: PBR material keys ignored (shading is Phong; `albedo` is read as "
            "diffuse): metallic, roughness (x2), translucency, type (x2)");
}

TEST(RayParserLights, DefaultAttenuation) {
  const std::string body =
      "point_light { position = (0, 0, 1); }\n"
      "point_light { position = (0, 0, 1); linear_attenuation_coeff = 0.5; }\n"
      "spot_light { position = (0, 0, 1); direction = (0, 0, -1); }\n"
      "directional_light { direction = (0, 0, -1); }\n";
  SceneDesc plain = parse(body);
  EXPECT_EQ(plain.lights[0].attenConstant, 0);
  EXPECT_EQ(plain.lights[0].attenQuadratic, 1);
  ParseOptions o;
  o.defaultAttenuation = std::array<float, 3>{0.25f, 0.25f, 0.25f};
  SceneDesc s = parse(body, o);
  ASSERT_EQ(s.lights.size(), 4u);
  for (size_t i : {size_t(0), size_t(2)}) {
    EXPECT_EQ(s.lights[i].attenConstant, 0.25f) << i;
    EXPECT_EQ(s.lights[i].attenLinear, 0.25f) << i;
    EXPECT_EQ(s.lights[i].attenQuadratic, 0.25f) << i;
  }
  // A light that sets any coefficient keeps the format's defaults for the others.
  EXPECT_EQ(s.lights[1].attenConstant, 0);
  EXPECT_EQ(s.lights[1].attenLinear, 0.5f);
  EXPECT_EQ(s.lights[1].attenQuadratic, 1);
}

// An area_light has no coefficients of its own: --default-attenuation reaches it (the
// COMP4411 soft-shadow sample), and without the option it keeps 1/d^2.
TEST(RayParserLights, DefaultAttenuationReachesAreaLights) {
  const std::string body = "area_light { u = (1, 0, 0); v = (0, 1, 0); }\n";
  SceneDesc plain = parse(body);
  ASSERT_EQ(plain.objects.size(), 1u);
  const LuminosityDesc& p = *plain.materials[size_t(plain.objects[0].material)].luminosity;
  EXPECT_EQ(p.attenConstant, 0);
  EXPECT_EQ(p.attenQuadratic, 1);
  ParseOptions o;
  o.defaultAttenuation = std::array<float, 3>{1, 0.5f, 0};
  SceneDesc s = parse(body, o);
  const LuminosityDesc& l = *s.materials[size_t(s.objects[0].material)].luminosity;
  EXPECT_EQ(l.attenConstant, 1);
  EXPECT_EQ(l.attenLinear, 0.5f);
  EXPECT_EQ(l.attenQuadratic, 0);
}

}  // namespace
}  // namespace lc::io

// ---------------------------------------------------------------------------------------
// environment_light and sun_sky_light (issue 24)

namespace lc::io {
namespace {

TEST(RayParserEnvironment, EnvironmentLightReadsEveryField) {
  SceneDesc s = parse(
      "environment_light { map = \"sky.hdr\"; colour = (1, 0.5, 0.25); intensity = 2; up = (0, 0, 2);\n"
      "  rotate = 90; lights = 1000; visible = false; }\n"
      "environment_light { }\n");
  ASSERT_EQ(s.environments.size(), 2u);
  const EnvironmentDesc& e = s.environments[0];
  EXPECT_EQ(e.kind, EnvironmentKind::Map);
  ASSERT_TRUE(e.map);
  EXPECT_EQ(e.map->path, "/base/sky.hdr");
  EXPECT_TRUE(e.map->srgb);  // 8-bit maps are sRGB-decoded
  expectVec(e.colour, 1, 0.5f, 0.25f);
  EXPECT_EQ(e.intensity, 2);
  expectVec(e.up, 0, 0, 2);
  EXPECT_EQ(e.rotateDegrees, 90);
  EXPECT_EQ(e.lights, 1000);
  EXPECT_FALSE(e.visible);
  EXPECT_EQ(e.loc.line, 2);
  const EnvironmentDesc& d = s.environments[1];
  EXPECT_FALSE(d.map);
  expectVec(d.colour, 1, 1, 1);
  EXPECT_EQ(d.lights, 4096);
  EXPECT_TRUE(d.visible);
}

TEST(RayParserEnvironment, SunSkyLightReadsEveryField) {
  SceneDesc s = parse("sun_sky_light { direction = (1, -2, 0); turbidity = 4.5; intensity = 3; lights = 512;\n"
                      "  ground = (0.1, 0.2, 0.3); visible = false; }\n");
  ASSERT_EQ(s.environments.size(), 1u);
  const EnvironmentDesc& e = s.environments[0];
  EXPECT_EQ(e.kind, EnvironmentKind::SunSky);
  expectVec(e.sunDirection, 1, -2, 0);
  EXPECT_EQ(e.turbidity, 4.5f);
  EXPECT_EQ(e.intensity, 3);
  EXPECT_EQ(e.lights, 512);
  expectVec(e.ground, 0.1f, 0.2f, 0.3f);
  EXPECT_FALSE(e.visible);
}

TEST(RayParserEnvironment, BadValuesAreErrorsAtTheirPlace) {
  EXPECT_EQ(error("environment_light { lights = 0; }"), "t.ray:2:30: error: lights must be >= 1, got 0");
  EXPECT_EQ(error("environment_light { lights = 2.5; }"),
            "t.ray:2:30: error: expected an integer for lights, got number 2.5");
  EXPECT_EQ(error("environment_light { intensity = -1; }"),
            "t.ray:2:33: error: intensity must be >= 0, got -1");
  EXPECT_EQ(error("environment_light {\n  colour = (1, -1, 0); }"),
            "t.ray:3:12: error: environment_light colour must be >= 0 in every component");
  EXPECT_EQ(error("environment_light { up = (0, 0, 0); }"), "t.ray:2:26: error: up must not be zero");
  EXPECT_EQ(error("environment_light { map = (1); }"),
            "t.ray:2:27: error: expected a file name (\"sky.hdr\"), got '('");
  EXPECT_EQ(error("environment_light { glow = 1; }"),
            "t.ray:2:21: error: unknown keyword 'glow' in environment_light");
  EXPECT_EQ(error("environment_light { visible = 1; }"), "t.ray:2:31: error: expected true or false, got number 1");
  EXPECT_EQ(error("sun_sky_light { direction = (0, 1, 0); }"),
            "t.ray:2:29: error: the sun must be above the horizon: direction (where sunlight travels) needs y < 0");
  EXPECT_EQ(error("sun_sky_light { turbidity = 1; }"),
            "t.ray:2:29: error: turbidity must be in [2, 10] (the range of Preetham's model), got 1");
  EXPECT_EQ(error("sun_sky_light { ground = (0, -0.5, 0); }"),
            "t.ray:2:26: error: ground must be >= 0 in every component");
  EXPECT_EQ(error("sun_sky_light { map = \"x.hdr\"; }"), "t.ray:2:17: error: unknown keyword 'map' in sun_sky_light");
  EXPECT_EQ(error("{ sun_sky_light { } }"), "t.ray:2:3: error: expected a primitive, transform or '{', got 'sun_sky_light'");
  ParseOptions few;
  few.limits.maxLights = 100;
  EXPECT_EQ(error("environment_light { lights = 101; }", few),
            "t.ray:2:30: error: lights 101 is more than the limit of 100 (raise it with --max-lights)");
}

}  // namespace
}  // namespace lc::io

namespace lc::io {
namespace {

// The parser reports how much of the text it has read: non-decreasing shares, ending at 1
// (the CLI's "scene" progress bar for large files).
TEST(RayParserProgress, SharesOfTheTextRiseToOne) {
  std::string text = "SBT-raytracer 1.0\n";
  for (int i = 0; i < 20000; ++i) text += "translate(" + std::to_string(i) + ",0,0, sphere {})\n";
  std::vector<double> seen;
  ParseOptions o;
  o.progress = [&](double f) { seen.push_back(f); };
  SceneDesc d = parseRayString(text, "big.ray", ".", o);
  EXPECT_EQ(d.objects.size(), 20000u);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
}

}  // namespace
}  // namespace lc::io
