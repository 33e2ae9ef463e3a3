// End-to-end tests of the `lightcuts` binary (its path comes from LC_BINARY, set by ctest):
//   - every row of the error catalogue (docs/ERRORS.md): the exact message on stderr
//     (file:line:column where the input has one), exit status 1, and no output file;
//   - the resource limits (--max-triangles, --max-lights, --max-vpls, --max-image-pixels,
//     --max-texture-pixels, --max-nesting), each with a small limit;
//   - interruption: SIGINT/SIGTERM during a render leave an existing output untouched,
//     write OUT.partial.exr and exit 130 quickly;
//   - unwritable outputs fail before rendering.
// Each test runs the binary in a fresh temporary directory, so paths in messages are
// the bare file names the test wrote.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/math.h"
#include "io/image.h"
#include "child_process.h"
#include "test_util.h"

namespace fs = std::filesystem;
using lc::testing::TempDir;
using lc::testing::filesIn;
using lc::testing::slurp;

namespace {

using Clock = std::chrono::steady_clock;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A running `lightcuts ARGS` process in `dir`, stdout/stderr captured to files there.
class Child : public lc::testing::ChildProcess {
 public:
  Child(const std::vector<std::string>& args, const std::string& dir)
      : ChildProcess(lc::testing::lightcutsCommand(args), dir) {}
};

struct CliResult {
  int status = -1;
  int signal = 0;
  bool timedOut = false;
  std::string out, err;
};

CliResult run(const std::vector<std::string>& args, const std::string& dir, double timeout = 300) {
  Child c(args, dir);
  CliResult r;
  r.timedOut = !c.wait(timeout);
  r.status = c.status();
  r.signal = c.termSignal();
  r.out = c.stdoutText();
  r.err = c.stderrText();
  return r;
}

const std::string kHeader = "SBT-raytracer 1.0\n";

// ---------------------------------------------------------------------------------------
// The error catalogue: one row per class of bad input (docs/ERRORS.md lists the same rows
// with the same names). Each row writes its input files, runs the command with `-o
// out.png` (render) and expects exactly `lightcuts: <message>\n` on stderr, exit 1, and
// no file other than the inputs afterwards (no output, no temporary).

struct Row {
  std::string name;
  std::vector<std::pair<std::string, std::string>> files;  // name, content ("@junk": 64 junk bytes)
  std::vector<std::string> args;                           // the command line after `lightcuts`
  std::string message;                                     // stderr without "lightcuts: " and "\n"
  int status = 1;
};

Row ray(std::string name, std::string body, std::string message, std::vector<std::string> extra = {}) {
  Row r;
  r.name = name;
  r.files = {{name + ".ray", kHeader + body}};
  r.args = {"render", name + ".ray", "-o", "out.png", "-q"};
  for (auto& e : extra) r.args.push_back(e);
  r.message = std::move(message);
  return r;
}

Row objRow(std::string name, std::string body, std::string message) {
  Row r;
  r.name = name;
  r.files = {{name + ".obj", body}};
  r.args = {"render", name + ".obj", "-o", "out.png", "-q"};
  r.message = std::move(message);
  return r;
}

const std::string kTri = "points = ((0,0,0),(1,0,0),(0,1,0));";
const std::string kLenientHint =
    "\nlightcuts: hint: --lenient skips unknown keywords (and their values) with a warning instead of failing";

std::vector<Row> catalogue() {
  std::vector<Row> rows = {
      // ---- lexical and syntax errors
      ray("syntax_error", "camera { position (1,2,3); }",
          "syntax_error.ray:2:19: error: expected '=', got '('"),
      ray("missing_header", "", ""),  // replaced below: an empty file has no header at all
      ray("unexpected_character", "sphere { @ }",
          "unexpected_character.ray:2:10: error: unexpected character '@'"),
      ray("unterminated_comment", "/* never closed\nsphere {}",
          "unterminated_comment.ray:2:1: error: unterminated comment"),
      ray("unterminated_string", "obj_mesh { file = \"abc\n}",
          "unterminated_string.ray:2:19: error: unterminated string"),
      ray("unclosed_transform", "translate(1,2,3, sphere {}",
          "unclosed_transform.ray:2:27: error: expected ')' to close translate opened at 2:1, got end of file"),
      ray("unclosed_group", "{ sphere {}",
          "unclosed_group.ray:2:12: error: expected '}' to close the group opened at 2:1, got end of file"),
      ray("unexpected_close", "sphere {} }",
          "unexpected_close.ray:2:11: error: unexpected '}' (no block is open)"),
      ray("wrong_type", "cylinder { capped = 1; }",
          "wrong_type.ray:2:21: error: expected true or false, got number 1"),
      // ---- keywords
      // (unknown keywords get a second line, a hint: kLenientHint)
      ray("unknown_keyword", "sphere { radius = 2; }",
          "unknown_keyword.ray:2:10: error: unknown keyword 'radius' in sphere" + kLenientHint),
      ray("unknown_item", "teapot { size = 1; }", "unknown_item.ray:2:1: error: unknown keyword 'teapot'" + kLenientHint),
      ray("duplicate_list", std::string("trimesh { ") + kTri + " points = ((0,0,0)); }",
          "duplicate_list.ray:2:47: error: 'points' is given twice in trimesh"),
      ray("second_camera", "camera {} camera {}",
          "second_camera.ray:2:11: error: a second camera (the first is at 2:1)"),
      ray("unknown_material", "sphere { material = nosuch; }",
          "unknown_material.ray:2:21: error: unknown material 'nosuch'"),
      ray("duplicate_material", "material = { name = a; }\nmaterial = { name = a; }",
          "duplicate_material.ray:3:21: error: material 'a' is already declared (at duplicate_material.ray:2:12)"),
      // ---- arity and numbers
      ray("wrong_arity", "camera { position = (1,2); }",
          "wrong_arity.ray:2:21: error: expected 3 numbers, got 2"),
      ray("bad_number", "camera { fov = 1.2.3; }", "bad_number.ray:2:16: error: malformed number '1.2.3'"),
      ray("number_overflow", "camera { fov = 1e999; }",
          "number_overflow.ray:2:16: error: number '1e999' is out of range"),
      ray("nan", "camera { fov = nan; }", "nan.ray:2:16: error: expected a number, got 'nan'"),
      ray("float_overflow", "point_light { position = (1e300, 0, 0); }",
          "float_overflow.ray:2:27: error: number 1e300 is out of range for a float"),
      ray("coordinate_too_large", "camera { position = (0,0,1e19); }",
          "coordinate_too_large.ray:2:26: error: number 1e19 is too large for a coordinate (at most 1e15 in magnitude)"),
      ray("index_too_large", "sphere { material = { transmissive = (1,1,1); index = 1e20; }; }",
          "index_too_large.ray:2:55: error: index must be at most 1000, got 1e20"),
      ray("value_out_of_range", "camera { fov = 200; }",
          "value_out_of_range.ray:2:16: error: fov must be between 0 and 180 degrees, got 200"),
      ray("fov_rounds_to_180", "camera { fov = 179.99999999; }",
          "fov_rounds_to_180.ray:2:16: error: fov must be between 0 and 180 degrees, got 180 "
          "(179.99999999 rounds to 180 in single precision)"),
      ray("negative_attenuation", "point_light { constant_attenuation_coeff = -1; }",
          "negative_attenuation.ray:2:44: error: constant_attenuation_coeff must be >= 0, got -1"),
      ray("negative_density", "sphere { material = { luminosity = { density = -1; }; }; }",
          "negative_density.ray:2:48: error: density must be >= 0, got -1"),
      // ---- meshes
      ray("index_out_of_range", std::string("trimesh { ") + kTri + " faces = ((0,1,5)); }",
          "index_out_of_range.ray:2:61: error: face index 5 is out of range (the mesh has 3 points)"),
      ray("index_huge", std::string("trimesh { ") + kTri + " faces = ((0,1,99999999999)); }",
          "index_huge.ray:2:61: error: face index 99999999999 is out of range (the mesh has 3 points)"),
      ray("index_not_integer", std::string("trimesh { ") + kTri + " faces = ((0,1,1.5)); }",
          "index_not_integer.ray:2:61: error: face index 1.5 is not an integer"),
      ray("face_too_small", std::string("trimesh { ") + kTri + " faces = ((0,1)); }",
          "face_too_small.ray:2:56: error: a face needs at least 3 indices, got 2"),
      ray("count_mismatch", std::string("trimesh { ") + kTri + " faces = ((0,1,2)); normals = ((0,0,1)); }",
          "count_mismatch.ray:2:66: error: trimesh has 3 points but 1 normals"),
      ray("mesh_without_faces", std::string("trimesh { ") + kTri + " }",
          "mesh_without_faces.ray:2:1: error: trimesh needs points and faces"),
      // ---- geometry
      ray("singular_scale", "scale(0, sphere {})",
          "singular_scale.ray:2:7: error: scale factor must not be zero (the transform would be singular)"),
      ray("singular_transform", "transform((1,0,0,0),(0,1,0,0),(0,0,0,0),(0,0,0,1), sphere {})",
          "singular_transform.ray:2:1: error: transform matrix is singular"),
      ray("transform_last_row", "transform((1,0,0,0),(0,1,0,0),(0,0,1,0),(1,0,0,1), sphere {})",
          "transform_last_row.ray:2:41: error: the last row of a transform must be (0,0,0,1)"),
      ray("zero_rotation_axis", "rotate(0,0,0,1, sphere {})",
          "zero_rotation_axis.ray:2:8: error: rotate axis must not be zero"),
      ray("parallel_camera", "camera { viewdir = (0,1,0); updir = (0,2,0); }",
          "parallel_camera.ray:2:37: error: viewdir and updir are parallel"),
      ray("degenerate_cone", "cone { bottom_radius = 0; }",
          "degenerate_cone.ray:2:1: error: cone has bottom_radius and top_radius both 0"),
      ray("degenerate_area_light", "area_light { u = (1,0,0); v = (2,0,0); }",
          "degenerate_area_light.ray:2:1: error: area_light has zero area (u and v are parallel or zero)"),
      ray("area_light_overflow", "area_light { position = (3e38,0,0); u = (1e38,0,0); v = (0,1,0); }",
          "area_light_overflow.ray:2:26: error: number 3e38 is too large for a coordinate (at most 1e15 in magnitude)"),
      // ---- files
      ray("missing_obj", "obj_mesh { file = \"nothere.obj\"; }",
          "missing_obj.ray:2:1: error: cannot open OBJ file 'nothere.obj': No such file or directory"),
      ray("missing_texture", "sphere { material = { diffuse = map(\"nothere.png\"); }; }",
          "missing_texture.ray:2:33: error: cannot open texture 'nothere.png': No such file or directory"),
      ray("obj_not_regular", "obj_mesh { file = \"/dev/zero\"; }",
          "obj_not_regular.ray:2:1: error: cannot open OBJ file '/dev/zero': not a regular file"),
      ray("texture_not_regular", "sphere { material = { diffuse = map(\"/dev/zero\"); }; }",
          "texture_not_regular.ray:2:33: error: cannot open texture '/dev/zero': not a regular file"),
      // ---- OBJ input
      objRow("obj_index_out_of_range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n",
             "obj_index_out_of_range.obj:4: error: vertex index 7 is out of range: the file has 3 'v' lines"),
      objRow("obj_index_zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
             "obj_index_zero.obj:4: error: face has vertex index 0 (or a non-number); OBJ indices start at 1"),
      objRow("obj_negative_index", "v 0 0 0\nf -1 -2 -3\nv 1 0 0\nv 0 1 0\n",
             "obj_negative_index.obj:2: error: vertex index -2 is out of range: only 1 'v' lines precede it"),
      objRow("obj_nan", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
             "obj_nan.obj:1: error: vertex coordinate 'nan' is not a finite number"),
      objRow("obj_inf", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n",
             "obj_inf.obj:2: error: vertex coordinate '1e999' is not a finite number"),
  };
  // Rows that need more than one .ray body.
  rows[1].message = "missing_header.ray:1:1: error: expected the header 'SBT-raytracer 1.0', got end of file";
  rows[1].files = {{"missing_header.ray", ""}};
  {
    // Issue 23: one huge polygon (tinyobj's triangulation is quadratic in its size).
    std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
    for (int i = 0; i < 4097; ++i) body += " " + std::to_string(i % 3 + 1);
    rows.push_back(objRow("obj_huge_polygon", body + "\n",
                          "obj_huge_polygon.obj:4: error: face has 4097 vertices, more than 4096 in one polygon "
                          "(split it into smaller faces)"));
  }

  {
    Row r;
    r.name = "missing_scene";
    r.args = {"render", "nothere.ray", "-o", "out.png", "-q"};
    r.message = "cannot open 'nothere.ray': No such file or directory";
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "scene_not_regular";
    r.args = {"render", "/dev/zero", "-o", "out.png", "-q"};
    r.message = "cannot read '/dev/zero': not a regular file";
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "scene_is_directory";
    r.files = {{"adir/.keep", ""}};
    r.args = {"render", "adir", "-o", "out.png", "-q"};
    r.message = "cannot read 'adir': it is a directory";
    rows.push_back(r);
  }
  {
    Row r = ray("unreadable_texture", "sphere { material = { diffuse = map(\"junk.png\"); }; }",
                "unreadable_texture.ray:2:33: error: cannot read texture 'junk.png': unknown image type");
    r.files.push_back({"junk.png", "@junk"});
    rows.push_back(r);
  }
  {
    // Issue 30: PNG and JPEG textures are read by libpng and libjpeg-turbo; a cut file is an
    // error naming it, not a texture filled with grey.
    Row r = ray("truncated_png_texture", "sphere { material = { diffuse = map(\"cut.png\"); }; }",
                "truncated_png_texture.ray:2:33: error: cannot read texture 'cut.png': truncated PNG: the file "
                "ends before the image data does");
    r.files.push_back({"cut.png", std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0", 18)});
    rows.push_back(r);
  }
  {
    Row r = ray("truncated_jpeg_texture", "sphere { material = { diffuse = map(\"cut.jpg\"); }; }",
                "truncated_jpeg_texture.ray:2:33: error: cannot read texture 'cut.jpg': truncated JPEG: the file "
                "ends before the image data does");
    r.files.push_back({"cut.jpg", std::string("\xff\xd8\xff\xdb\x00\x43\x00", 7)});
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "unreadable_image";
    r.files = {{"junk.png", "@junk"}, {"b.ppm", "P6\n1 1\n255\nabc"}};
    r.args = {"compare", "junk.png", "b.ppm"};
    r.message = "cannot read image 'junk.png': unknown image type";
    rows.push_back(r);
  }
  {
    // Issue 23: a truncated image read as valid (RMSE 0 from uninitialised memory).
    Row r;
    r.name = "truncated_image";
    r.files = {{"a.ppm", "P6\n2 1\n255\nabcdef"}, {"trunc.ppm", "P6\n2 1\n255\nabc"}};
    r.args = {"compare", "a.ppm", "trunc.ppm"};
    r.message = "cannot read image 'trunc.ppm': truncated PNM data: 3 bytes of samples, the header needs 6";
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "image_size_mismatch";
    r.files = {{"a.ppm", "P6\n2 1\n255\nabcdef"}, {"b.ppm", "P6\n1 1\n255\nabc"}};
    r.args = {"compare", "a.ppm", "b.ppm"};
    r.message = "cannot compare images of different sizes: reference is 2x1, test is 1x1";
    rows.push_back(r);
  }
  // ---- outputs (checked before anything is loaded or rendered)
  {
    Row r = ray("unknown_image_format", "sphere {}",
                "cannot write 'out.xyz': unknown image format '.xyz' (use .png, .ppm, .bmp or .exr)");
    r.args = {"render", "unknown_image_format.ray", "-o", "out.xyz", "-q"};
    rows.push_back(r);
  }
  {
    Row r = ray("unwritable_output", "sphere {}", "cannot write 'missing/out.png': No such file or directory");
    r.args = {"render", "unwritable_output.ray", "-o", "missing/out.png", "-q"};
    rows.push_back(r);
  }
  {
    Row r = ray("output_under_file", "sphere {}", "cannot write 'afile/out.png': Not a directory");
    r.files.push_back({"afile", "x"});
    r.args = {"render", "output_under_file.ray", "-o", "afile/out.png", "-q"};
    rows.push_back(r);
  }
  {
    Row r = ray("unwritable_stats", "sphere {}", "cannot write 'missing/stats.json': No such file or directory",
                {"--stats", "missing/stats.json"});
    rows.push_back(r);
  }
  // ---- colliding paths (issue 23: the later write used to win, or the input was overwritten)
  rows.push_back(ray("stats_is_the_image", "sphere {}",
                     "'out.png' is given as both -o and --stats; use different files",
                     {"--stats", "out.png"}));
  rows.push_back(ray("heatmap_is_the_image", "sphere {}",
                     "'./out.png' (--cut-heatmap) is the same file as 'out.png' (-o); use different files",
                     {"--cut-heatmap", "./out.png"}));
  {
    Row r = ray("output_is_the_scene", "sphere {}",
                "'output_is_the_scene.ray' is given as both the scene and -o; use different files");
    r.args = {"render", "output_is_the_scene.ray", "-o", "output_is_the_scene.ray", "-q"};
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "obj2ray_overwrites_input";
    r.files = {{"in.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"}};
    r.args = {"obj2ray", "in.obj", "-o", "in.obj"};
    r.message = "'in.obj' is given as both the input OBJ and -o; use different files";
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "obj2ray_default_output_is_input";
    r.files = {{"in.ray", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"}};
    r.args = {"obj2ray", "in.ray"};
    r.message = "'in.ray' is given as both the input OBJ and the default output (the input with .ray; choose another "
                "with -o); use different files";
    rows.push_back(r);
  }
  {
    Row r;
    r.name = "heatmap_overwrites_reference";
    r.files = {{"a.ppm", "P6\n1 1\n255\nabc"}, {"b.ppm", "P6\n1 1\n255\nabc"}};
    r.args = {"compare", "a.ppm", "b.ppm", "--heatmap", "a.ppm"};
    r.message = "'a.ppm' is given as both the reference image and --heatmap; use different files";
    rows.push_back(r);
  }
  // ---- limits (the tests in CliLimits below cover each flag in more detail)
  rows.push_back(ray("limit_triangles",
                     "trimesh { points = ((0,0,0),(1,0,0),(0,1,0),(1,1,0)); "
                     "faces = ((0,1,2),(0,1,3),(0,2,3),(1,2,3),(0,1,2)); }",
                     "limit_triangles.ray:2:96: error: more triangles than the limit of 4 (raise it with --max-triangles)",
                     {"--max-triangles", "4"}));
  rows.push_back(ray("limit_lights", "point_light {} point_light {} point_light {}",
                     "limit_lights.ray:2:31: error: more lights than the limit of 2 (raise it with --max-lights)",
                     {"--max-lights", "2"}));
  rows.push_back(ray("limit_nesting", "{ { { { sphere {} } } } }",
                     "limit_nesting.ray:2:5: error: nesting deeper than the limit of 2 levels (raise it with --max-nesting)",
                     {"--max-nesting", "2"}));
  rows.push_back(ray("limit_image_pixels", "sphere {}", "an image of 100x100 exceeds --max-image-pixels (1000)",
                     {"--width", "100", "--height", "100", "--max-image-pixels", "1000"}));
  rows.push_back(ray("aov_needs_exr", "sphere {}",
                     "--aov needs an .exr output (its layers are extra EXR channels); 'out.png' is .png",
                     {"--aov", "depth"}));
  rows.push_back(ray("aov_unknown", "sphere {}",
                     "--aov: unknown output 'dpth\\x1b' (use albedo, normal, depth, cut, shadow_rays, samples, comma-separated)",
                     {"--aov", "albedo,dpth\x1b"}));
  rows.push_back(ray("aspect_ratio_too_wide", "camera { aspectratio = 3e9; }",
                     "aspectratio 3000000000 makes the image 3000000000x1: more than 65536 pixels wide (give both --width and --height)",
                     {"--height", "1"}));
  rows.push_back(ray("aspect_ratio_too_high", "camera { aspectratio = 0.0001; }",
                     "aspectratio 0.0001 makes the image 10x100000: more than 65536 pixels high (give both --width and --height)",
                     {"--width", "10"}));
  rows.push_back(ray("limit_objects", "sphere {} sphere {} sphere {}",
                     "limit_objects.ray:2:21: error: more objects and materials than the limit of 3 (raise it with --max-objects)",
                     {"--max-objects", "3"}));
  {
    Row r = ray("output_without_extension", "sphere {}",
                "cannot write 'out': no file extension to choose the format (use .png, .ppm, .bmp or .exr)");
    r.args = {"render", "output_without_extension.ray", "-o", "out", "-q"};
    rows.push_back(r);
  }
  return rows;
}

void PrintTo(const Row& r, std::ostream* os) { *os << r.name; }

class ErrorCatalogue : public ::testing::TestWithParam<Row> {};

TEST_P(ErrorCatalogue, MessageStatusAndNoOutput) {
  const Row& row = GetParam();
  TempDir dir;
  for (const auto& [name, content] : row.files) {
    fs::create_directories(fs::path(dir.file(name)).parent_path());
    if (name.size() > 5 && name.substr(name.size() - 5) == ".keep") continue;
    writeText(dir.file(name), content == "@junk" ? std::string(64, '\x5a') : content);
  }
  std::set<std::string> before = filesIn(dir.path());
  CliResult r = run(row.args, dir.path());
  ASSERT_FALSE(r.timedOut);
  EXPECT_EQ(r.signal, 0) << r.err;
  EXPECT_EQ(r.status, row.status);
  EXPECT_EQ(r.err, "lightcuts: " + row.message + "\n");
  EXPECT_EQ(filesIn(dir.path()), before) << "the command left a file behind";
}

INSTANTIATE_TEST_SUITE_P(Rows, ErrorCatalogue, ::testing::ValuesIn(catalogue()),
                         [](const ::testing::TestParamInfo<Row>& i) { return i.param.name; });

// Issue 26: `lightcuts` alone prints the help (the subcommands, one line each) on stdout
// and exits 0, as --help does; it used to say only "A subcommand is required".
TEST(CliUsage, NoSubcommandPrintsTheHelp) {
  TempDir dir;
  CliResult r = run({}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("Subcommands:"), std::string::npos) << r.out;
  for (const char* cmd : {"render", "info", "compare", "obj2ray"}) {
    size_t at = r.out.find(std::string("\n  ") + cmd + " ");
    ASSERT_NE(at, std::string::npos) << cmd << " is not listed:\n" << r.out;
    size_t eol = r.out.find('\n', at + 1);
    std::string line = r.out.substr(at + 1, eol - at - 1);
    EXPECT_GT(line.size(), std::string(cmd).size() + 10) << "no description on the line of " << cmd;
  }
  EXPECT_EQ(r.out.find("A subcommand is required"), std::string::npos) << r.out;
  // --help prints the same.
  CliResult h = run({"--help"}, dir.path());
  EXPECT_EQ(h.status, 0);
  EXPECT_EQ(h.out, r.out);
}

// Issue 26: obj2ray without -o writes IN with its extension replaced by .ray, next to IN.
TEST(CliObj2Ray, DefaultOutputIsTheInputWithRayExtension) {
  TempDir dir;
  fs::create_directories(dir.file("models"));
  writeText(dir.file("models/cube.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  CliResult r = run({"obj2ray", "models/cube.obj"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "wrote models/cube.ray\n");
  ASSERT_TRUE(fs::exists(dir.file("models/cube.ray")));
  EXPECT_EQ(slurp(dir.file("models/cube.ray")).rfind(kHeader, 0), 0u);
  CliResult h = run({"obj2ray", "--help"}, dir.path());
  EXPECT_NE(h.out.find("default: the input with its extension replaced by .ray"), std::string::npos) << h.out;
}

// Issue 26: `render --help` is grouped (Output, Image, Lightcuts, Reconstruction, Scene,
// Lights & GI, Limits) and every option states its default; every option keeps its name.
TEST(CliUsage, RenderHelpIsGroupedAndStatesEveryDefault) {
  TempDir dir;
  CliResult r = run({"render", "--help"}, dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string& h = r.out;
  std::vector<size_t> at;
  for (const char* g : {"Output:", "Image:", "Lightcuts:", "Reconstruction:", "Scene:", "Lights & GI:", "Limits:"}) {
    at.push_back(h.find(std::string("\n") + g + "\n"));
    EXPECT_NE(at.back(), std::string::npos) << "no group " << g << ":\n" << h;
  }
  EXPECT_TRUE(std::is_sorted(at.begin(), at.end())) << h;
  for (const char* name :
       {"-o,--output", "--stats", "--cut-heatmap", "--tonemap", "--exposure", "-q,--quiet", "--width", "--height", "--spp",
        "--max-depth", "--threads", "--seed", "--method", "--tree", "--error", "--max-cut", "--cut-criterion",
        "--estimator", "--visibility-probes", "--clear-clusters", "--reference-pixels", "--reconstruct", "--reconstruct-coarse", "--reconstruct-split",
        "--lenient", "--object-lights", "--object-light-placement", "--emission-density", "--default-attenuation",
        "--vpls", "--bounces", "--vpl-normalize", "--vpl-clamp", "--caustics", "--caustic-lights",
        "--caustic-smoothing", "--gi", "--max-lights", "--max-vpls",
        "--max-triangles", "--max-nesting", "--max-objects", "--max-image-pixels", "--max-texture-pixels"}) {
    size_t p = h.find(std::string("\n  ") + name + " ");
    ASSERT_NE(p, std::string::npos) << name << " is missing:\n" << h;
    // The option's entry: up to the next option or group (a long name puts the text on a line of its own).
    size_t next = std::min(h.find("\n  -", p + 1), h.find("\n\n", p + 1));
    std::string entry = h.substr(p + 1, next - p - 1);
    EXPECT_NE(entry.find("default"), std::string::npos) << "no default stated: " << entry;
  }
  // A few values, as the code defines them.
  EXPECT_NE(h.find("Most nodes in one cut (a cut stopped there has not met --error"), std::string::npos) << h;
  EXPECT_NE(h.find("with a warning over 0.1% of the cuts); default 16000"), std::string::npos) << h;
  EXPECT_NE(h.find("default 512, or from --height"), std::string::npos) << h;
  EXPECT_NE(h.find("Limit on VPLs; default 10000000"), std::string::npos) << h;
  EXPECT_NE(h.find("default auto: 4 for images of 512 x 512 pixels or more"), std::string::npos) << h;
  EXPECT_NE(h.find("default the scene's, else 0.05"), std::string::npos) << h;
}

// A usage error is CLI11's: its own message and status (not 1), and no output.
TEST(CliUsage, UnknownOptionIsAUsageError) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--bogus"}, dir.path());
  EXPECT_EQ(r.status, 109);
  EXPECT_NE(r.err.find("The following argument was not expected: --bogus"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("out.png")));
}

TEST(CliUsage, OutOfRangeOptionIsAUsageError) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "0"}, dir.path());
  EXPECT_EQ(r.status, 105);
  EXPECT_NE(r.err.find("--width: Value 0 not in range 1 to 65536"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("out.png")));
}

// Issue 23: limits take whole numbers >= 0; -1 used to wrap around to no limit at all
// (--max-lights, --max-image-pixels) or to read "a limit of -1 levels" (--max-nesting).
TEST(CliUsage, NegativeLimitsAreUsageErrors) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "point_light {} sphere {}");
  for (const char* flag : {"--max-lights", "--max-vpls", "--max-triangles", "--max-nesting", "--max-objects",
                           "--max-image-pixels", "--max-texture-pixels"}) {
    for (const char* value : {"-1", "1.5", "x"}) {
      CliResult r = run({"render", "s.ray", "-o", "out.png", "-q", flag, value}, dir.path());
      EXPECT_EQ(r.status, 105) << flag << " " << value << ": " << r.err;
      EXPECT_NE(r.err.find(std::string(flag) + ": a limit must be a whole number >= 0 (0 allows none), got " + value),
                std::string::npos)
          << r.err;
      EXPECT_FALSE(fs::exists(dir.file("out.png")));
    }
  }
  // 0 is a limit like any other: it allows none.
  CliResult r = run({"info", "s.ray", "--max-lights", "0"}, dir.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("more lights than the limit of 0"), std::string::npos) << r.err;
}

// A valid scene renders: status 0 and the file exists (the baseline for the rows above).
TEST(CliRender, ValidSceneWritesTheImage) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "camera { position = (0,0,4); }\npoint_light { position = (0,0,4); }\n"
                                          "sphere { material = { diffuse = (1,1,1); }; }");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "-q", "--width", "32"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.file("out.png")));
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"s.ray", "out.png"}));
}

// Reconstruction cuts are on by default for lightcuts from 512 x 512 pixels (every 4
// pixels, 8 from 1024 x 1024), off below or on request, and reported.
TEST(CliRender, ReconstructionCutsByDefaultAndOffOnRequest) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "camera { position = (0,0,4); }\npoint_light { position = (0,0,4); }\n"
                                          "point_light { position = (1,1,4); }\n"
                                          "sphere { material = { diffuse = (1,1,1); }; }");
  auto stats = [&](std::vector<std::string> extra, const char* width = "32") {
    std::vector<std::string> args = {"render", "s.ray", "-o", "out.png", "-q", "--width", width, "--stats", "s.json"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(slurp(dir.file("s.json")));
  };
  nlohmann::json a = stats({}, "512");
  EXPECT_EQ(a["reconstruct_spacing"].get<int>(), 4);
  EXPECT_GT(a["reconstruction_samples"].get<int>(), 0);
  EXPECT_GT(a["reconstructed_points"].get<int>(), 0);
  EXPECT_EQ(stats({})["reconstruct_spacing"].get<int>(), 0);  // under 512 x 512: full cuts
  // The spacing grows with the image's side, so that a cell spans the same share of the view.
  EXPECT_EQ(stats({}, "1023")["reconstruct_spacing"].get<int>(), 4);
  EXPECT_EQ(stats({"--height", "1080"}, "1920")["reconstruct_spacing"].get<int>(), 8);
  EXPECT_EQ(stats({"--reconstruct", "4"})["reconstruct_spacing"].get<int>(), 4);
  nlohmann::json b = stats({"--reconstruct", "0"}, "512");
  EXPECT_EQ(b["reconstruct_spacing"].get<int>(), 0);
  EXPECT_EQ(b["reconstructed_points"].get<int>(), 0);
  EXPECT_EQ(b["reconstruction_samples"].get<int>(), 0);
  nlohmann::json c = stats({"--method", "brute"});
  EXPECT_EQ(c["reconstruct_spacing"].get<int>(), 0);
  EXPECT_EQ(c["reconstruct_coarse_spacing"].get<int>(), 0);
  // Coarse cells: twice the spacing by default (a plain lit sphere: its cells agree),
  // off or larger on request; any other size is refused.
  EXPECT_EQ(a["reconstruct_coarse_spacing"].get<int>(), 8);
  EXPECT_GT(a["reconstruction_coarse_cells"].get<int>(), 0);
  EXPECT_EQ(b["reconstruct_coarse_spacing"].get<int>(), 0);
  nlohmann::json d = stats({"--reconstruct-coarse", "0"}, "512");
  EXPECT_EQ(d["reconstruction_coarse_cells"].get<int>(), 0);
  EXPECT_GT(d["reconstruction_samples"].get<int>(), a["reconstruction_samples"].get<int>());
  EXPECT_EQ(stats({"--reconstruct", "4", "--reconstruct-coarse", "16"})["reconstruct_coarse_spacing"].get<int>(), 16);
  for (const char* bad : {"12", "4", "2"}) {
    CliResult r = run({"render", "s.ray", "-o", "bad.png", "-q", "--width", "32", "--reconstruct", "4",
                       "--reconstruct-coarse", bad},
                      dir.path());
    EXPECT_NE(r.status, 0) << bad;
    EXPECT_NE(r.err.find("--reconstruct-coarse"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.file("bad.png")));
  }
}

// --seed reaches the VPL paths (issue 22): with brute force at one sample per pixel the VPLs
// are the image's only randomness, so two seeds give different images and one seed the same
// bytes; an explicit --seed overrides the scene's instant_radiosity seed, and without one the
// scene's seed stands.
TEST(CliRender, SeedDrivesTheVpls) {
  TempDir dir;
  // A lit floor and a wall beside it: a few VPLs on the floor light the wall visibly.
  const std::string body =
      "camera { position = (0,1,4); viewdir = (0,-0.2,-1); }\n"
      "point_light { position = (0.5,1.5,0.5); colour = (1,1,1); }\n"
      "translate(0,0,0, rotate(1,0,0,-1.5708, scale(4, square { material = { diffuse = (0.9,0.9,0.9); }; })))\n"
      "translate(-1,1,0, rotate(0,1,0,1.5708, scale(4, square { material = { diffuse = (0.9,0.9,0.9); }; })))\n";
  writeText(dir.file("s.ray"), kHeader + "instant_radiosity { vpls = 20; }\n" + body);
  writeText(dir.file("s7.ray"), kHeader + "instant_radiosity { vpls = 20; seed = 7; }\n" + body);
  auto image = [&](const std::string& scene, std::vector<std::string> extra) {
    // (--aa off: antialiasing's jitter follows --seed too, not the scene's VPL seed)
    std::vector<std::string> args = {"render", scene, "-o", "out.ppm", "-q", "--width", "32", "--method", "brute",
                                     "--aa", "off"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    return slurp(dir.file("out.ppm"));
  };
  std::string noSeed = image("s.ray", {}), one = image("s.ray", {"--seed", "1"});
  std::string seven = image("s.ray", {"--seed", "7"});
  ASSERT_FALSE(one.empty());
  EXPECT_NE(one, seven);
  EXPECT_EQ(seven, image("s.ray", {"--seed", "7"}));
  EXPECT_EQ(noSeed, one);  // the default seed is 1
  EXPECT_EQ(image("s7.ray", {}), seven);
  EXPECT_EQ(image("s7.ray", {"--seed", "1"}), one);
  // Without VPLs (and antialiasing's jitter) the seed changes nothing under brute force.
  EXPECT_EQ(image("s.ray", {"--gi", "off", "--seed", "1"}), image("s.ray", {"--gi", "off", "--seed", "7"}));
}

// Issue 25: --caustics N (over the scene's instant_radiosity caustics) and the stats' keys.
TEST(CliRender, CausticsAreReportedInTheStats) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader +
                                   "instant_radiosity { caustics = 1000; caustic_lights = vpl; }\n"
                                   "camera { position = (0,5,6); look_at = (0,0.6,0); }\n"
                                   "point_light { position = (0,8,0); colour = (48,48,48); }\n"
                                   "rotate(1,0,0,-1.5708, scale(16, square { material = { diffuse = (0.8,0.8,0.8); }; }))\n"
                                   "translate(0,1.6,0, sphere { material = { transmissive = (0.9,0.9,0.9); index = 1.5; }; })\n");
  CliResult r = run({"render", "s.ray", "-o", "out.ppm", "-q", "--width", "16", "--caustics", "200000", "--stats", "s.json"},
                    dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(dir.file("s.json")));
  EXPECT_GT(j["caustic_lights"].get<uint64_t>(), 500u);  // ~0.5% of the paths reach the ball
  EXPECT_EQ(j["caustics"]["paths"].get<uint64_t>(), 200000u);
  EXPECT_EQ(j["caustics"]["kind"].get<std::string>(), "vpl");  // the scene's
  EXPECT_GE(j["caustics"]["time_s"].get<double>(), 0.0);
  EXPECT_EQ(j["lights"]["total"].get<uint64_t>(), j["caustic_lights"].get<uint64_t>() + 1);
}

// A scene can come from a pipe (e.g. `lightcuts render <(generator)`): it is read up to
// the file size limit.
TEST(CliRender, SceneFromAPipe) {
  TempDir dir;
  std::string fifo = dir.file("scene.ray");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  std::thread writer([&] {
    // Non-blocking open, retried until the reader is there, so that a reader that never
    // comes cannot hang the test.
    int fd = -1;
    for (int i = 0; i < 3000 && fd < 0; ++i) {
      fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (fd < 0) return;
    fcntl(fd, F_SETFL, 0);
    std::string text = kHeader + "camera { position = (0,0,4); }\npoint_light { position = (0,0,4); }\nsphere {}\n";
    EXPECT_EQ(write(fd, text.data(), text.size()), ssize_t(text.size()));
    close(fd);
  });
  CliResult r = run({"render", "scene.ray", "-o", "out.png", "-q", "--width", "16"}, dir.path(), 60);
  writer.join();
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.file("out.png")));
}

// ---------------------------------------------------------------------------------------
// Resource limits: each flag, with a small value, names itself in the error; the same
// input passes with the limit raised.

struct LimitCase {
  std::string name;
  std::string body;                 // .ray body (after the header)
  std::vector<std::string> tight;   // flags that make it fail
  std::vector<std::string> loose;   // flags under which it loads
  std::string message;
};

void PrintTo(const LimitCase& c, std::ostream* os) { *os << c.name; }

class CliLimits : public ::testing::TestWithParam<LimitCase> {};

TEST_P(CliLimits, FailsNamingTheFlagAndPassesWhenRaised) {
  const LimitCase& c = GetParam();
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + c.body);
  fs::copy_file(lc::testing::dataPath("public-scenes/checkerboard.bmp"), dir.file("checkerboard.bmp"));
  fs::copy_file(lc::testing::dataPath("models/cube.obj"), dir.file("cube.obj"));

  std::vector<std::string> args = {"info", "s.ray"};
  for (const auto& f : c.tight) args.push_back(f);
  CliResult bad = run(args, dir.path());
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err, "lightcuts: " + c.message + "\n");

  args = {"info", "s.ray"};
  for (const auto& f : c.loose) args.push_back(f);
  CliResult ok = run(args, dir.path());
  EXPECT_EQ(ok.status, 0) << ok.err;
}

const std::string kQuad5 =
    "trimesh { points = ((0,0,0),(1,0,0),(0,1,0),(1,1,0)); faces = ((0,1,2),(0,1,3),(0,2,3),(1,2,3),(0,1,2)); }";

INSTANTIATE_TEST_SUITE_P(
    Flags, CliLimits,
    ::testing::Values(
        LimitCase{"triangles", kQuad5, {"--max-triangles", "4"}, {"--max-triangles", "5"},
                  "s.ray:2:96: error: more triangles than the limit of 4 (raise it with --max-triangles)"},
        LimitCase{"vertices", kQuad5, {"--max-triangles", "3"}, {"--max-triangles", "5"},
                  "s.ray:2:45: error: more vertices than the limit of 3 (raise it with --max-triangles)"},
        LimitCase{"triangles_across_meshes", kQuad5 + "\n" + kQuad5, {"--max-triangles", "9"},
                  {"--max-triangles", "10"},
                  "s.ray:3:96: error: more triangles than the limit of 9 (raise it with --max-triangles)"},
        LimitCase{"obj_triangles", "obj_mesh { file = \"cube.obj\"; }", {"--max-triangles", "11"},
                  {"--max-triangles", "12"},
                  "s.ray:2:1: error: OBJ file 'cube.obj' has 12 triangles, more than the limit of 11 "
                  "(raise it with --max-triangles)"},
        LimitCase{"lights", "point_light {} point_light {} point_light {}", {"--max-lights", "2"},
                  {"--max-lights", "3"},
                  "s.ray:2:31: error: more lights than the limit of 2 (raise it with --max-lights)"},
        LimitCase{"vpls", "instant_radiosity { vpls = 100; }", {"--max-vpls", "99", "--gi", "off"},
                  {"--max-vpls", "100", "--gi", "off"},
                  "s.ray:2:28: error: vpls 100 is more than the limit of 99 (raise it with --max-vpls)"},
        LimitCase{"texture_pixels", "sphere { material = { diffuse = map(\"checkerboard.bmp\"); }; }",
                  {"--max-texture-pixels", "291595"}, {"--max-texture-pixels", "291596"},
                  "s.ray:2:33: error: texture 'checkerboard.bmp' is 542x538 = 291596 pixels, more than "
                  "--max-texture-pixels (291595)"},
        LimitCase{"nesting", "translate(0,0,0, translate(0,0,0, translate(0,0,0, sphere {})))",
                  {"--max-nesting", "2"}, {"--max-nesting", "3"},
                  "s.ray:2:35: error: nesting deeper than the limit of 2 levels (raise it with --max-nesting)"},
        LimitCase{"nesting_groups", "{ { { sphere {} } } }", {"--max-nesting", "2"}, {"--max-nesting", "3"},
                  "s.ray:2:5: error: nesting deeper than the limit of 2 levels (raise it with --max-nesting)"},
        LimitCase{"nesting_skipped_values", "teapot = ((((1))));", {"--lenient", "--max-nesting", "3"},
                  {"--lenient", "--max-nesting", "4"},
                  "s.ray:2:13: error: nesting deeper than the limit of 3 levels (raise it with --max-nesting)"}),
    [](const ::testing::TestParamInfo<LimitCase>& i) { return i.param.name; });

// The image size limit applies to render (info has no image).
TEST(CliLimitsRender, ImagePixels) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  CliResult bad = run({"render", "s.ray", "-o", "out.png", "-q", "--width", "40", "--height", "25",
                 "--max-image-pixels", "999"},
                dir.path());
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err, "lightcuts: an image of 40x25 exceeds --max-image-pixels (999)\n");
  EXPECT_FALSE(fs::exists(dir.file("out.png")));
  CliResult ok = run({"render", "s.ray", "-o", "out.png", "-q", "--width", "40", "--height", "25",
                "--max-image-pixels", "1000"},
               dir.path());
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(fs::exists(dir.file("out.png")));
}

// Input far deeper than any limit fails cleanly at the default limit (no stack overflow):
// groups, transforms and the values --lenient skips.
TEST(CliLimitsRender, DeepNestingFailsAtTheDefaultLimit) {
  TempDir dir;
  writeText(dir.file("groups.ray"), kHeader + std::string(200000, '{'));
  std::string transforms;
  for (int i = 0; i < 50000; ++i) transforms += "translate(0,0,0,";
  writeText(dir.file("transforms.ray"), kHeader + transforms);
  writeText(dir.file("skipped.ray"), kHeader + "teapot = " + std::string(200000, '('));
  for (auto [file, column] : {std::pair<std::string, int>{"groups.ray", 1001}, {"transforms.ray", 16001},
                              {"skipped.ray", 1010}}) {
    SCOPED_TRACE(file);
    CliResult r = run({"info", file, "--lenient"}, dir.path());
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "lightcuts: " + file + ":2:" + std::to_string(column) +
                         ": error: nesting deeper than the limit of 1000 levels (raise it with --max-nesting)\n");
  }
}

// Lights from a luminosity's density: the object lights count is checked against
// --max-lights before any light is made.
TEST(CliLimitsRender, ObjectLightsFromDensity) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader +
                                   "square { material = { luminosity = { density = 1e6; intensity = 1; }; }; }\n");
  CliResult bad = run({"info", "s.ray", "--max-lights", "1000"}, dir.path());
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err,
            "lightcuts: s.ray:2:23: error: luminous objects need 2000000 lights (2000000 with the scene's "
            "other lights), more than --max-lights (1000)\n");
  CliResult ok = run({"info", "s.ray", "--max-lights", "2000000"}, dir.path());
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// --vpls beyond --max-vpls from the command line.
TEST(CliLimitsRender, VplsFromTheCommandLine) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "point_light { position = (0,0,2); }\nsphere {}\n");
  CliResult bad = run({"info", "s.ray", "--vpls", "100", "--max-vpls", "10"}, dir.path());
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err, "lightcuts: 100 VPL paths requested, more than --max-vpls (10)\n");
  CliResult ok = run({"info", "s.ray", "--vpls", "100", "--max-vpls", "100"}, dir.path());
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// --max-memory: one budget over items, meshes, lights and the image, counted before they
// are allocated (core/memory_budget.h). Each case fails at a budget just under its need and
// passes just above it.
TEST(CliLimitsMemory, EachConsumerIsCountedAgainstOneBudget) {
  TempDir dir;
  fs::copy_file(lc::testing::dataPath("models/cube.obj"), dir.file("cube.obj"));
  fs::copy_file(lc::testing::dataPath("public-scenes/checkerboard.bmp"), dir.file("a.bmp"));
  fs::copy_file(lc::testing::dataPath("public-scenes/checkerboard.bmp"), dir.file("b.bmp"));
  // Two textures: each fits the budget alone, both do not (counted across files).
  writeText(dir.file("tex.ray"), kHeader + "sphere { material = { diffuse = map(\"a.bmp\"); }; }\n"
                                           "sphere { material = { diffuse = map(\"b.bmp\"); }; }\n");
  writeText(dir.file("items.ray"), kHeader + "sphere {} sphere {} sphere {} sphere {}\n");
  writeText(dir.file("obj.ray"), kHeader + "obj_mesh { file = \"cube.obj\"; }\n");
  writeText(dir.file("lum.ray"),
            kHeader + "square { material = { luminosity = { density = 1000; intensity = 1; }; }; }\n");
  writeText(dir.file("vpl.ray"), kHeader + "point_light { position = (0,0,2); }\nsphere {}\n");
  struct Case {
    std::vector<std::string> args;
    std::string tight, loose, message;
  };
  const Case cases[] = {
      {{"info", "items.ray"}, "4K", "8K",
       "items.ray:2:31: error: 5 objects and materials need about 6.2 KB, more than --max-memory (4.0 KB)"},
      {{"info", "obj.ray"}, "4K", "8K",
       "obj.ray:2:1: error: the 12 triangles of OBJ file 'cube.obj' need about 3.5 KB (4.8 KB with what is "
       "already loaded), more than --max-memory (4.0 KB)"},
      {{"info", "lum.ray"}, "600K", "800K",
       "lum.ray:2:23: error: the 2000 lights of luminous objects need about 625.0 KB, more than --max-memory "
       "(600.0 KB)"},
      {{"info", "tex.ray"}, "6M", "12M",
       "tex.ray:3:33: error: the 542x538 pixels of 'b.bmp' need about 4.4 MB (8.9 MB with what is already loaded), "
       "more than --max-memory (6.0 MB)"},
      {{"info", "vpl.ray", "--vpls", "1000"}, "300K", "400K",
       "1000 VPLs need about 312.5 KB, more than --max-memory (300.0 KB)"},
      {{"render", "vpl.ray", "-o", "i.png", "-q", "--width", "100", "--height", "100"}, "300K", "400K",
       "the 100x100 image's buffers need about 312.5 KB, more than --max-memory (300.0 KB)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[1]);
    std::vector<std::string> args = c.args;
    args.insert(args.end(), {"--max-memory", c.tight});
    CliResult bad = run(args, dir.path());
    EXPECT_EQ(bad.status, 1);
    EXPECT_EQ(bad.err, "lightcuts: " + c.message + "\n");
    EXPECT_FALSE(fs::exists(dir.file("i.png")));
    args.back() = c.loose;
    CliResult ok = run(args, dir.path());
    EXPECT_EQ(ok.status, 0) << ok.err;
  }
  CliResult junk = run({"info", "items.ray", "--max-memory", "1.5.0"}, dir.path());
  EXPECT_EQ(junk.status, 105);
  EXPECT_NE(junk.err.find("a memory size must be bytes >= 0, or with K/M/G/T (8G), got 1.5.0"), std::string::npos)
      << junk.err;
}

// ---------------------------------------------------------------------------------------
// Interruption and output safety

// A scene that takes minutes to render by brute force: 600 point lights over a plane.
std::string slowScene() {
  std::string s = kHeader + "camera { position = (0,0,10); viewdir = (0,0,-1); }\n";
  for (int i = 0; i < 600; ++i)
    s += "point_light { position = (" + std::to_string(i % 25 - 12) + "," + std::to_string(i / 25 - 12) +
         ",3); colour = (0.01,0.01,0.01); }\n";
  s += "scale(20, square { material = { diffuse = (1,1,1); }; })\nsphere { material = { diffuse = (1,0,0); }; }\n";
  return s;
}

void interruptTest(int sig) {
  TempDir dir;
  writeText(dir.file("slow.ray"), slowScene());
  const std::string old = "previous image: must survive the interruption byte for byte";
  writeText(dir.file("out.png"), old);
  Child c({"render", "slow.ray", "-o", "out.png", "--method", "brute", "--width", "1600", "--height", "1600",
           "--threads", "2"},
          dir.path());
  // The progress line appears once rendering has run for a second: the handlers are set.
  ASSERT_TRUE(c.waitForStderr("rendering", 120)) << c.stderrText();
  auto t0 = Clock::now();
  c.signal(sig);
  ASSERT_TRUE(c.wait(30));
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(c.termSignal(), 0);
  EXPECT_EQ(c.status(), 128 + sig) << c.stderrText();  // 130 for SIGINT, 143 for SIGTERM
  EXPECT_LT(seconds, 2.0) << "took " << seconds << " s to stop";
  EXPECT_EQ(slurp(dir.file("out.png")), old);
  EXPECT_TRUE(fs::exists(dir.file("out.png.partial.exr")));
  EXPECT_GT(fs::file_size(dir.file("out.png.partial.exr")), 1000u);
  EXPECT_NE(c.stderrText().find("interrupted; out.png untouched, partial image in out.png.partial.exr"),
            std::string::npos)
      << c.stderrText();
  // Nothing else is left behind (no temporary files).
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"slow.ray", "out.png", "out.png.partial.exr"}));
}

TEST(CliInterrupt, SigintKeepsTheOldOutputAndWritesThePartialImage) { interruptTest(SIGINT); }
TEST(CliInterrupt, SigtermKeepsTheOldOutputAndWritesThePartialImage) { interruptTest(SIGTERM); }

// Issue 23: the flag was checked only between 16 x 16 tiles, so an image of one tile ran to
// the end (exit 0, the old output replaced). It is checked at every pixel now.
TEST(CliInterrupt, SigtermStopsInsideASingleTile) {
  TempDir dir;
  writeText(dir.file("slow.ray"), slowScene());
  const std::string old = "previous image";
  writeText(dir.file("out.png"), old);
  // 16 x 16 pixels, 4096 samples of 600 lights each: minutes on one thread.
  Child c({"render", "slow.ray", "-o", "out.png", "--method", "brute", "--width", "16", "--height", "16", "--spp",
           "4096", "--threads", "2"},
          dir.path());
  ASSERT_TRUE(c.waitForStderr("rendering", 120)) << c.stderrText();
  auto t0 = Clock::now();
  c.signal(SIGTERM);
  ASSERT_TRUE(c.wait(30));
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(c.termSignal(), 0);
  EXPECT_EQ(c.status(), 143) << c.stderrText();
  EXPECT_LT(seconds, 2.0) << "took " << seconds << " s to stop";
  EXPECT_EQ(slurp(dir.file("out.png")), old);
  EXPECT_TRUE(fs::exists(dir.file("out.png.partial.exr")));
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"slow.ray", "out.png", "out.png.partial.exr"}));
}

// Issue 23: shooting VPLs ignored the signals' flag (the handlers were set only for the
// render); it is checked per block of paths, and the run exits as an interrupted render.
TEST(CliInterrupt, SigtermStopsVplShooting) {
  TempDir dir;
  writeText(dir.file("room.ray"), kHeader + "camera { position = (0,0,0); viewdir = (0,0,-1); }\n"
                                            "point_light { position = (0,0,0); colour = (1,1,1); }\n"
                                            "scale(10, sphere { material = { diffuse = (0.8,0.8,0.8); }; })\n");
  writeText(dir.file("out.png"), "old");
  Child c({"render", "room.ray", "-o", "out.png", "--width", "8", "--vpls", "40000000", "--bounces", "4",
           "--max-vpls", "100000000", "--threads", "2"},
          dir.path());
  ASSERT_TRUE(c.waitForStderr("VPLs", 120)) << c.stderrText();
  auto t0 = Clock::now();
  c.signal(SIGTERM);
  ASSERT_TRUE(c.wait(30));
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(c.termSignal(), 0);
  EXPECT_EQ(c.status(), 143) << c.stderrText();
  EXPECT_LT(seconds, 2.0) << "took " << seconds << " s to stop";
  EXPECT_NE(c.stderrText().find("lightcuts: interrupted; out.png untouched"), std::string::npos) << c.stderrText();
  EXPECT_EQ(slurp(dir.file("out.png")), "old");
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"room.ray", "out.png"}));
}

// An unwritable output fails at once, before the (long) render, and writes nothing.
TEST(CliInterrupt, UnwritableOutputFailsBeforeRendering) {
  TempDir dir;
  writeText(dir.file("slow.ray"), slowScene());
  auto t0 = Clock::now();
  CliResult r = run({"render", "slow.ray", "-o", "missing/out.png", "--method", "brute", "--width", "1600"}, dir.path());
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lightcuts: cannot write 'missing/out.png': No such file or directory\n");
  EXPECT_LT(seconds, 20.0);
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"slow.ray"}));
}

// Permissions cannot stop root, so this one runs only as an ordinary user.
TEST(CliInterrupt, ReadOnlyDirectory) {
  if (geteuid() == 0) GTEST_SKIP() << "running as root: permissions are not enforced";
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  fs::create_directory(dir.file("ro"));
  chmod(dir.file("ro").c_str(), 0555);
  CliResult r = run({"render", "s.ray", "-o", "ro/out.png", "-q"}, dir.path());
  chmod(dir.file("ro").c_str(), 0755);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lightcuts: cannot write 'ro/out.png': Permission denied\n");
  EXPECT_TRUE(fs::is_empty(dir.file("ro")));
}

// Issue 23: outputs were written to a temporary file renamed over the path, whatever sat
// there. `--stats /dev/null` (as root) turned /dev/null into a JSON file.
TEST(CliOutputTarget, DeviceNodeIsWrittenNotReplaced) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "8", "-q", "--stats", "/dev/null"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  struct stat st;
  ASSERT_EQ(stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null is no longer a character device";
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"s.ray", "out.png"}));
}

// A symlink is followed: its target gets the image, the link stays a link.
TEST(CliOutputTarget, SymlinkTargetIsWritten) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  fs::create_directory(dir.file("real"));
  writeText(dir.file("real/out.png"), "old");
  fs::create_symlink("real/out.png", dir.file("link.png"));
  fs::create_symlink("real/new.png", dir.file("dangling.png"));
  CliResult r = run({"render", "s.ray", "-o", "link.png", "--width", "8", "-q"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir.file("link.png")));
  EXPECT_EQ(slurp(dir.file("real/out.png")).substr(1, 3), "PNG");
  r = run({"render", "s.ray", "-o", "dangling.png", "--width", "8", "-q"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir.file("dangling.png")));
  EXPECT_EQ(slurp(dir.file("real/new.png")).substr(1, 3), "PNG");
  EXPECT_EQ(filesIn(dir.file("real")), (std::set<std::string>{"out.png", "new.png"}));
}

// A read-only file (0444) in a writable folder is refused, before the render, even for root.
TEST(CliOutputTarget, ReadOnlyFileIsRefused) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + "sphere {}");
  writeText(dir.file("out.png"), "old");
  chmod(dir.file("out.png").c_str(), 0444);
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "8", "-q"}, dir.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lightcuts: cannot write 'out.png': it is read-only\n");
  EXPECT_EQ(slurp(dir.file("out.png")), "old");
  writeText(dir.file("stats.json"), "{}");
  chmod(dir.file("stats.json").c_str(), 0444);
  r = run({"render", "s.ray", "-o", "new.png", "--width", "8", "-q", "--stats", "stats.json"}, dir.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lightcuts: cannot write 'stats.json': it is read-only\n");
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"s.ray", "out.png", "stats.json"}));
}

// A failed render (bad input) leaves an existing output as it was.
TEST(CliInterrupt, ErrorKeepsTheOldOutput) {
  TempDir dir;
  writeText(dir.file("bad.ray"), kHeader + "sphere { radius = 1; }");
  writeText(dir.file("out.png"), "old");
  CliResult r = run({"render", "bad.ray", "-o", "out.png", "-q"}, dir.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(slurp(dir.file("out.png")), "old");
}

// ---------------------------------------------------------------------------------------
// Warnings that explain a surprising image (issue 26): one line each on stderr,
// "lightcuts: warning: ..." or "lightcuts: hint: ...", printed under -q too.

// The lines of stderr that are warnings or hints.
std::vector<std::string> notes(const std::string& err) {
  std::vector<std::string> out;
  size_t at = 0;
  while (at < err.size()) {
    size_t eol = err.find('\n', at);
    if (eol == std::string::npos) eol = err.size();
    std::string line = err.substr(at, eol - at);
    if (line.rfind("lightcuts: warning: ", 0) == 0 || line.rfind("lightcuts: hint: ", 0) == 0) out.push_back(line);
    at = eol + 1;
  }
  return out;
}

const std::string kLitFloor =
    "camera { position = (0,1,4); viewdir = (0,-0.2,-1); }\n"
    "translate(0,-1,0, rotate(1,0,0,-1.5708, scale(8, square { material = { diffuse = (0.8,0.8,0.8); }; })))\n"
    "sphere { material = { diffuse = (0.8,0.3,0.2); }; }\n";

TEST(CliWarnings, NoneForAnOrdinaryScene) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + kLitFloor + "point_light { position = (2,4,3); colour = (1,1,1); }\n");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "24", "-q"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

TEST(CliWarnings, NoLights) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + kLitFloor);
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "24", "-q"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(notes(r.err), std::vector<std::string>{
                              "lightcuts: warning: the scene has no lights: only emissive and ambient colours will "
                              "show (add a point_light, directional_light, spot_light or area_light, or a luminosity "
                              "to a material)"});
  EXPECT_TRUE(fs::exists(dir.file("out.png")));
}

// Cuts out of --max-cut nodes before their bound holds: the pixels may be off by more
// than --error, and the render says so (with the share); with the default budget, not.
TEST(CliWarnings, CutsStoppedByMaxCut) {
  TempDir dir;
  std::string lights;
  for (int i = 0; i < 40; ++i)
    lights += "point_light { position = (" + std::to_string(i % 8 - 4) + ", 3, " + std::to_string(i / 8 - 2) +
              "); colour = (0.1,0.1,0.1); }\n";
  writeText(dir.file("s.ray"), kHeader + kLitFloor + lights);
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "24", "-q", "--max-cut", "2"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  std::vector<std::string> n = notes(r.err);
  ASSERT_EQ(n.size(), 1u) << r.err;
  EXPECT_EQ(n[0].rfind("lightcuts: warning: ", 0), 0u) << n[0];
  EXPECT_NE(n[0].find("% of the cuts stopped at --max-cut 2 before their error bound held: those pixels may be "
                      "further from brute force than --error (raise --max-cut)"),
            std::string::npos)
      << n[0];
  EXPECT_TRUE(fs::exists(dir.file("out.png")));
  r = run({"render", "s.ray", "-o", "out.png", "--width", "24", "-q"}, dir.path());
  EXPECT_EQ(r.err, "");
}

TEST(CliWarnings, BlackImageSaysWhy) {
  TempDir dir;
  // The light inside the sphere: every shadow ray from the outside is blocked.
  writeText(dir.file("inside.ray"), kHeader + kLitFloor + "point_light { position = (0,0,0); colour = (1,1,1); }\n");
  // The camera looking away from everything.
  writeText(dir.file("away.ray"), kHeader + "camera { position = (0,1,4); viewdir = (0,0,1); }\n" +
                                      kLitFloor.substr(kLitFloor.find('\n') + 1) +
                                      "point_light { position = (2,4,3); colour = (1,1,1); }\n");
  // A light whose quadratic attenuation leaves about 1e-5 of it at the scene.
  writeText(dir.file("weak.ray"), kHeader + kLitFloor +
                                      "point_light { position = (2,4,3); colour = (1,1,1); "
                                      "constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; "
                                      "quadratic_attenuation_coeff = 3000; }\n");
  auto warning = [&](const std::string& scene, std::vector<std::string> extra = {}, std::string out = "out.png") {
    std::vector<std::string> args = {"render", scene, "-o", out, "--width", "24", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    std::vector<std::string> n = notes(r.err);
    return n.empty() ? std::string() : n[0] + (n.size() > 1 ? " (and more)" : "");
  };
  std::string inside = warning("inside.ray");
  EXPECT_EQ(inside.rfind("lightcuts: warning: the image is", 0), 0u) << inside;
  EXPECT_NE(inside.find("black: everything is in shadow (100% of the shadow rays found their light blocked); a "
                        "light may be inside or behind an object"),
            std::string::npos)
      << inside;
  EXPECT_EQ(warning("inside.ray", {"--method", "brute"}), inside);
  std::string away = warning("away.ray");
  EXPECT_EQ(away.rfind("lightcuts: warning: the image is black: the camera sees almost nothing (0 shading points "
                       "from 576 camera rays)", 0),
            0u)
      << away;
  std::string weak = warning("weak.ray");
  EXPECT_NE(weak.find("black: the light reaching the surfaces is too weak to show; check the lights' colours and "
                      "their attenuation"),
            std::string::npos)
      << weak;
  EXPECT_NE(weak.find("or raise --exposure"), std::string::npos) << weak;
  // Raised by 2^16, the same scene shows: no warning; the 8-bit file is judged as written.
  EXPECT_EQ(warning("weak.ray", {"--exposure", "16"}), "");
  // An EXR is judged as it would be displayed (sRGB).
  EXPECT_NE(warning("weak.ray", {}, "out.exr").find("too weak"), std::string::npos);
  EXPECT_EQ(warning("weak.ray", {"--exposure", "16"}, "out.exr"), "");
}

TEST(CliWarnings, EmissiveObjWithoutGiHintsAtVpls) {
  TempDir dir;
  // A floor and a small lamp (Ke) above it, facing down.
  writeText(dir.file("lamp.mtl"), "newmtl floor\nKd 0.8 0.8 0.8\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
  writeText(dir.file("lamp.obj"),
            "mtllib lamp.mtl\nv -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nv -0.3 2 -0.3\nv 0.3 2 -0.3\nv 0.3 2 "
            "0.3\nv -0.3 2 0.3\nusemtl floor\nf 1 4 3 2\nusemtl lamp\nf 5 6 7 8\n");
  const std::string hint =
      "lightcuts: hint: the OBJ's emissive materials light what they see directly, nothing bounces; --vpls 10000 "
      "adds indirect light (global illumination)";
  CliResult r = run({"render", "lamp.obj", "-o", "out.png", "--width", "16", "-q"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(notes(r.err), std::vector<std::string>{hint});
  for (std::vector<std::string> flags : {std::vector<std::string>{"--vpls", "200"}, {"--gi", "off"}, {"--vpls", "0"}}) {
    std::vector<std::string> args = {"render", "lamp.obj", "-o", "out.png", "--width", "16", "-q"};
    args.insert(args.end(), flags.begin(), flags.end());
    CliResult g = run(args, dir.path());
    EXPECT_EQ(g.status, 0) << g.err;
    EXPECT_EQ(notes(g.err), std::vector<std::string>{}) << flags[0] << " " << flags[1];
  }
}

// The parser's warnings keep their location, in the errors' format.
TEST(CliWarnings, LenientWarningsCarryTheirLocation) {
  TempDir dir;
  writeText(dir.file("s.ray"),
            kHeader + kLitFloor + "point_light { position = (2,4,3); }\nsphere { radius = 2; }\n");
  CliResult r = run({"render", "s.ray", "-o", "out.png", "--width", "16", "-q", "--lenient"}, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "lightcuts: s.ray:6:10: warning: unknown keyword 'radius' in sphere (skipped)\n");
}

// ---------------------------------------------------------------------------------------
// Display-ready output (issue 26): 8-bit files are sRGB-encoded by default; --tonemap clamp
// stores the values as the course renderer did; --exposure scales before either; EXR stays
// linear. Metadata: scene, command line and version in PNG text chunks and EXR attributes.

TEST(CliOutput, DefaultIsSrgbClampKeepsTheCourseLookExposureScales) {
  TempDir dir;
  // An ambient-only sphere filling the view: every pixel is linear 0.25 exactly.
  writeText(dir.file("s.ray"), kHeader +
                                   "camera { position = (0,0,0.5); viewdir = (0,0,-1); }\n"
                                   "ambient_light { colour = (1,1,1); }\n"
                                   "sphere { material = { ambient = (0.25,0.25,0.25); diffuse = (0,0,0); }; }\n");
  auto centre = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", "s.ray", "-o", "o.ppm", "--width", "8", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    std::string ppm = slurp(dir.file("o.ppm"));
    return ppm.empty() ? -1 : int(uint8_t(ppm[ppm.size() - 3 * 36 - 1]));  // a pixel near the centre
  };
  EXPECT_EQ(centre({}), 137);                             // sRGB(0.25)
  EXPECT_EQ(centre({"--tonemap", "srgb"}), 137);
  EXPECT_EQ(centre({"--tonemap", "clamp"}), 64);          // round(0.25 * 255)
  EXPECT_EQ(centre({"--tonemap", "clamp", "--exposure", "1"}), 128);
  EXPECT_EQ(centre({"--exposure", "-2"}), 71);            // sRGB(0.0625)
  int filmic = centre({"--tonemap", "filmic"});
  EXPECT_GT(filmic, 64);
  EXPECT_LT(filmic, 137);
  // The stats name what was applied.
  CliResult r = run({"render", "s.ray", "-o", "o.exr", "--width", "8", "-q", "--exposure", "3", "--stats", "s.json"},
                    dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(dir.file("s.json")));
  EXPECT_EQ(j["tonemap"], "srgb");
  EXPECT_EQ(j["exposure"].get<double>(), 3.0);
  // Bad values: a usage error, no image.
  for (std::vector<std::string> bad : {std::vector<std::string>{"--tonemap", "aces"}, {"--exposure", "100"},
                                       {"--exposure", "nan"}}) {
    CliResult b = run({"render", "s.ray", "-o", "bad.png", "--width", "8", "-q", bad[0], bad[1]}, dir.path());
    EXPECT_NE(b.status, 0) << bad[1];
    EXPECT_NE(b.err.find(bad[0]), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir.file("bad.png")));
  }
}

// PNG tEXt chunks (read back with the PNG chunk walker's independent copy below) and EXR
// attributes (checked in io's tests) name the scene, the command line and the version.
TEST(CliOutput, PngCarriesSceneCommandLineAndVersion) {
  TempDir dir;
  writeText(dir.file("my scene.ray"), kHeader + kLitFloor + "point_light { position = (2,4,3); }\n");
  CliResult r = run({"render", "my scene.ray", "-o", "out.png", "--width", "16", "-q", "--exposure", "0.5"},
                    dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  std::string png = slurp(dir.file("out.png"));
  std::vector<std::pair<std::string, std::string>> text;
  for (size_t at = 8; at + 12 <= png.size();) {
    uint32_t len = uint32_t(uint8_t(png[at])) << 24 | uint32_t(uint8_t(png[at + 1])) << 16 |
                   uint32_t(uint8_t(png[at + 2])) << 8 | uint32_t(uint8_t(png[at + 3]));
    if (png.compare(at + 4, 4, "tEXt") == 0) {
      std::string body = png.substr(at + 8, len);
      text.emplace_back(body.substr(0, body.find('\0')), body.substr(body.find('\0') + 1));
    }
    at += 12 + len;
  }
  CliResult v = run({"--version"}, dir.path());
  ASSERT_FALSE(v.out.empty());
  std::vector<std::pair<std::string, std::string>> want = {
      {"Software", v.out.substr(0, v.out.size() - 1)},
      {"Scene", "my scene.ray"},
      {"Command line", "lightcuts render 'my scene.ray' -o out.png --width 16 -q --exposure 0.5"},
      {"Tone map", "srgb"},
      {"Exposure", "0.5"}};
  EXPECT_EQ(text, want);
}

// The OBJ default camera fits the model's bounding sphere vertically; a portrait image widens
// the view to fit it across too, so a cube keeps black margins left and right.
TEST(CliObjCamera, PortraitImageKeepsTheModelInFrame) {
  TempDir dir;
  writeText(dir.file("cube.obj"),
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
  auto columns = [&](int w, int h) {
    CliResult r = run({"render", "cube.obj", "-o", "c.ppm", "--width", std::to_string(w), "--height",
                       std::to_string(h), "-q"},
                      dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    std::string ppm = slurp(dir.file("c.ppm"));
    std::string header = "P6\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
    EXPECT_EQ(ppm.rfind(header, 0), 0u);
    // Brightest value in the left and right columns, and in the middle one.
    int edge = 0, middle = 0;
    for (int y = 0; y < h; ++y)
      for (int c = 0; c < 3; ++c) {
        auto at = [&](int x) { return int(uint8_t(ppm[header.size() + 3 * (size_t(y) * w + x) + c])); };
        edge = std::max({edge, at(0), at(w - 1)});
        middle = std::max(middle, at(w / 2));
      }
    return std::pair{edge, middle};
  };
  for (auto [w, h] : {std::pair{24, 48}, std::pair{48, 48}, std::pair{48, 24}}) {
    auto [edge, middle] = columns(w, h);
    EXPECT_EQ(edge, 0) << w << "x" << h;
    EXPECT_GT(middle, 50) << w << "x" << h;
  }
}

// compare: 8-bit inputs hold display-encoded values, and the command says so; EXR is linear.
TEST(CliWarnings, CompareOf8BitImagesSaysTheyAreDisplayEncoded) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + kLitFloor + "point_light { position = (2,4,3); }\n");
  for (const char* out : {"a.png", "a.exr"}) {
    CliResult r = run({"render", "s.ray", "-o", out, "--width", "16", "-q"}, dir.path());
    ASSERT_EQ(r.status, 0) << r.err;
  }
  CliResult png = run({"compare", "a.png", "a.png"}, dir.path());
  EXPECT_EQ(png.status, 0) << png.err;
  EXPECT_EQ(notes(png.err), std::vector<std::string>{
                                "lightcuts: warning: 'a.png' is an 8-bit image: its values are display-encoded (sRGB "
                                "unless rendered with --tonemap clamp), so the errors are not relative errors of "
                                "radiance; compare .exr renders for those"});
  CliResult exr = run({"compare", "a.exr", "a.exr"}, dir.path());
  EXPECT_EQ(exr.status, 0) << exr.err;
  EXPECT_EQ(exr.err, "");
}

}  // namespace

// --aov: extra layers of the EXR beside R, G, B, read back with OpenEXR (io::readExrChannel)
// and checked in closed form on a plane seen head on (albedo = its kd, normal = +z, depth =
// the distance along each pixel's ray); other formats refuse it before rendering.
TEST(CliOutput, AovLayersInTheExr) {
  TempDir dir;
  writeText(dir.file("plane.ray"), kHeader +
                                       "camera { position = (0,0,5); viewdir = (0,0,-1); updir = (0,1,0); fov = 60; }\n"
                                       "point_light { position = (0,0,3); colour = (1,1,1); }\n"
                                       "scale(10, square { material = { diffuse = (0.5,0.6,0.7); }; })\n");
  const int W = 12, H = 10;
  CliResult r = run({"render", "plane.ray", "-o", "out.exr", "--width", std::to_string(W), "--height",
                     std::to_string(H), "-q", "--aov", "albedo,normal,depth,cut,shadow_rays,samples"},
                    dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string exr = dir.file("out.exr");
  lc::io::Image img = lc::io::readImage(exr);  // the image is still R, G, B
  ASSERT_EQ(img.width, W);
  EXPECT_GT(lc::luminance(img.at(W / 2, H / 2)), 0.0f);
  int w = 0, h = 0;
  auto channel = [&](const std::string& name) {
    std::vector<float> v = lc::io::readExrChannel(exr, name, w, h);
    EXPECT_EQ(w, W);
    EXPECT_EQ(h, H);
    return v;
  };
  std::vector<float> ar = channel("albedo.R"), ag = channel("albedo.G"), ab = channel("albedo.B");
  std::vector<float> nx = channel("normal.X"), ny = channel("normal.Y"), nz = channel("normal.Z");
  std::vector<float> depth = channel("depth.Z"), cut = channel("cut.Y"), rays = channel("shadow_rays.Y");
  std::vector<float> samples = channel("samples.Y");
  const float tanHalf = std::tan(30.0f * 3.14159265f / 180.0f);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + size_t(x);
      EXPECT_FLOAT_EQ(ar[i], 0.5f);
      EXPECT_FLOAT_EQ(ag[i], 0.6f);
      EXPECT_FLOAT_EQ(ab[i], 0.7f);
      EXPECT_NEAR(nx[i], 0.0f, 1e-6f);
      EXPECT_NEAR(ny[i], 0.0f, 1e-6f);
      EXPECT_NEAR(nz[i], 1.0f, 1e-6f);
      // The ray through the pixel centre: (a, b, -1) with a, b on the image plane at distance 1.
      const float a = (2 * (float(x) + 0.5f) / W - 1) * tanHalf * float(W) / float(H);
      const float b = (2 * (float(y) + 0.5f) / H - 1) * tanHalf;
      EXPECT_NEAR(depth[i], 5.0f * std::sqrt(1 + a * a + b * b), 1e-3f) << x << "," << y;
      EXPECT_FLOAT_EQ(cut[i], 1.0f);   // one light: a cut of one node
      EXPECT_FLOAT_EQ(rays[i], 1.0f);  // and its shadow ray
      EXPECT_TRUE(samples[i] == 1.0f || samples[i] == 81.0f) << samples[i];  // the centre, or 9 x 9
    }
  // Names are checked; 8-bit outputs have no layers.
  CliResult png = run({"render", "plane.ray", "-o", "out.png", "--width", "8", "-q", "--aov", "depth"}, dir.path());
  EXPECT_EQ(png.status, 1);
  EXPECT_EQ(png.err, "lightcuts: --aov needs an .exr output (its layers are extra EXR channels); 'out.png' is .png\n");
  EXPECT_FALSE(fs::exists(dir.file("out.png")));
  CliResult bad = run({"render", "plane.ray", "-o", "b.exr", "--width", "8", "-q", "--aov", "depth,alpha"}, dir.path());
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("--aov: unknown output 'alpha'"), std::string::npos) << bad.err;
}

// Antialiasing is on by default (--aa adaptive), off with --aa off, and a fixed --spp
// count samples every pixel instead; the stats say which.
TEST(CliOutput, AdaptiveAntialiasingByDefault) {
  TempDir dir;
  writeText(dir.file("s.ray"), kHeader + kLitFloor + "point_light { position = (2,4,3); }\n");
  auto stats = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"render", "s.ray", "-o", "o.png", "--width", "32", "-q", "--stats", "s.json"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(slurp(dir.file("s.json")));
  };
  nlohmann::json d = stats({});
  EXPECT_EQ(d["aa"], "adaptive");
  EXPECT_GT(d["aa_pixels"].get<int>(), 20);  // the sphere's outline
  EXPECT_LT(d["aa_pixels"].get<int>(), 32 * 32 / 2);
  EXPECT_LE(d["aa_seam_pixels"].get<int>(), d["aa_pixels"].get<int>());
  EXPECT_EQ(d["primary_rays"].get<int>(), 32 * 32 + 80 * d["aa_pixels"].get<int>());  // the default 80
  nlohmann::json off = stats({"--aa", "off"});
  EXPECT_EQ(off["aa_pixels"].get<int>(), 0);
  EXPECT_EQ(off["primary_rays"].get<int>(), 32 * 32);
  nlohmann::json fixed = stats({"--spp", "4"});
  EXPECT_EQ(fixed["aa"], "off");
  EXPECT_EQ(fixed["primary_rays"].get<int>(), 4 * 32 * 32);
  nlohmann::json more = stats({"--aa-samples", "24"});
  EXPECT_EQ(more["primary_rays"].get<int>(), 32 * 32 + 24 * more["aa_pixels"].get<int>());
  EXPECT_EQ(more["aa_pixels"], d["aa_pixels"]);
  // The probe for a surface near sub-samples beyond their samples: on by default; off, it
  // sends no rays, so no more shadow rays than on (reconstruction forced at this size).
  EXPECT_EQ(d["aa_extrapolation_probe"], true);
  nlohmann::json probed = stats({"--reconstruct", "4"});
  nlohmann::json unprobed = stats({"--reconstruct", "4", "--aa-extrapolation-probe", "off"});
  EXPECT_EQ(unprobed["aa_extrapolation_probe"], false);
  EXPECT_LE(unprobed["shadow_rays"].get<double>(), probed["shadow_rays"].get<double>());
  // Sub-samples' full cuts as samples for the rest of their pixel: on by default; off,
  // every such sub-sample takes its own full cut, so no fewer than on.
  EXPECT_EQ(d["aa_pixel_samples"], true);
  nlohmann::json unshared = stats({"--reconstruct", "4", "--aa-pixel-samples", "off"});
  EXPECT_EQ(unshared["aa_pixel_samples"], false);
  EXPECT_GE(unshared["reconstruction_fallbacks"].get<double>(), probed["reconstruction_fallbacks"].get<double>());
  CliResult bad = run({"render", "s.ray", "-o", "b.png", "--width", "8", "-q", "--aa-samples", "16"}, dir.path());
  EXPECT_NE(bad.status, 0);
  // --aov samples: 81 at the re-sampled pixels, 1 elsewhere; --spp N everywhere.
  auto samples = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"render", "s.ray", "-o", "o.exr", "--width", "32", "-q", "--aov", "samples"};
    args.insert(args.end(), extra.begin(), extra.end());
    CliResult r = run(args, dir.path());
    EXPECT_EQ(r.status, 0) << r.err;
    int w = 0, h = 0;
    return lc::io::readExrChannel(dir.file("o.exr"), "samples.Y", w, h);
  };
  std::vector<float> s = samples({});
  EXPECT_EQ(std::count(s.begin(), s.end(), 81.0f), d["aa_pixels"].get<long>());
  EXPECT_EQ(std::count(s.begin(), s.end(), 1.0f), 32 * 32 - d["aa_pixels"].get<long>());
  std::vector<float> s4 = samples({"--spp", "4"});
  EXPECT_EQ(std::count(s4.begin(), s4.end(), 4.0f), 32 * 32);
}
