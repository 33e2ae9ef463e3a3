// Recursive-descent reader for .ray files (docs/SCENE_FORMAT.md). Transforms and groups
// are parsed with an explicit stack instead of recursion, so nesting depth is bounded
// only by Limits::maxNesting and never by the C++ stack.
#include "io/ray_parser.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <unordered_map>

#include "core/file_util.h"
#include "core/memory_budget.h"
#include "io/obj_loader.h"
#include "io/ray_lexer.h"

namespace lc::io {

namespace detail {

// Appends an OBJ file's mesh as one object: its materials go to the end of
// scene.materials and triangleMaterials are shifted to match, unless `overrideMaterial`
// is set (an explicit `material` in obj_mesh), which then applies to the whole mesh.
// `object` carries the transform, name and location; its kind/mesh/material are filled in.
void appendObjMesh(SceneDesc& scene, ObjData&& obj, ObjectDesc object,
                   std::optional<int> overrideMaterial, int defaultMaterial) {
  MeshDesc mesh = std::move(obj.mesh);
  if (overrideMaterial) {
    mesh.triangleMaterials.clear();
    mesh.vertexMaterials.clear();
    object.material = *overrideMaterial;
  } else {
    int base = int(scene.materials.size());
    int count = int(obj.materials.size());
    auto shift = [&](std::vector<int>& ids) {
      for (int& id : ids) {
        if (id < 0 || id >= count)
          throw Error(object.loc, "OBJ material index " + std::to_string(id) + " is out of range (" +
                                      std::to_string(count) + " materials)");
        id += base;
      }
    };
    shift(mesh.triangleMaterials);
    shift(mesh.vertexMaterials);
    for (MaterialDesc& m : obj.materials) scene.materials.push_back(std::move(m));
    // The object's own material is what a triangle without an entry would use.
    object.material = count > 0 ? base : defaultMaterial;
  }
  object.kind = ShapeKind::Mesh;
  object.mesh = int(scene.meshes.size());
  scene.meshes.push_back(std::move(mesh));
  scene.objects.push_back(std::move(object));
  for (std::string& w : obj.warnings) scene.warnings.push_back(std::move(w));
}

}  // namespace detail

namespace {

// Tokens hold views of the text (ray_lexer.h); messages join them to strings.
std::string operator+(std::string a, std::string_view b) { return a.append(b); }
std::string operator+(std::string_view a, const std::string& b) { return std::string(a).append(b); }
std::string operator+(const char* a, std::string_view b) { return std::string(a).append(b); }
std::string operator+(std::string_view a, const char* b) { return std::string(a).append(b); }

std::string quoteChar(char c) { return std::string("'") + c + "'"; }

bool oneOf(std::string_view w, std::initializer_list<const char*> words) {
  for (const char* x : words)
    if (w == x) return true;
  return false;
}

bool isTransformWord(const Token& t) {
  return t.kind == TokenKind::Ident && !t.quoted &&
         (t.word == "translate" || t.word == "rotate" || t.word == "scale" || t.word == "transform");
}

bool isPrimitiveWord(const Token& t) {
  if (t.kind != TokenKind::Ident || t.quoted) return false;
  const std::string_view w = t.word;
  return w == "sphere" || w == "box" || w == "square" || w == "cylinder" || w == "cone" ||
         w == "trimesh" || w == "obj_mesh" || w == "sphere_light";
}

bool isTopLevelOnlyWord(const Token& t) {
  if (t.kind != TokenKind::Ident || t.quoted) return false;
  const std::string_view w = t.word;
  return w == "camera" || w == "ambient_light" || w == "point_light" || w == "directional_light" ||
         w == "spot_light" || w == "area_light" || w == "instant_radiosity" || w == "environment_light" ||
         w == "sun_sky_light";
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& name, const std::string& baseDir,
         const ParseOptions& options)
      : lex_(text, name), baseDir_(baseDir), opt_(options) {
    scene_.path = name;
  }

  SceneDesc run();

 private:
  // ---- errors -------------------------------------------------------------------------
  [[noreturn]] void fail(const Token& t, const std::string& msg) const { throw Error(lex_.loc(t), msg); }
  // Objects and materials cost memory per item whatever their text: bound their number.
  void checkItemLimit(const Token& at) const {
    if (scene_.objects.size() + scene_.materials.size() >= opt_.limits.maxObjects)
      fail(at, "more objects and materials than the limit of " + std::to_string(opt_.limits.maxObjects) +
                   " (raise it with --max-objects)");
    if (!processBudget().tryReserve(memory_cost::kRayItem)) {
      const uint64_t n = scene_.objects.size() + scene_.materials.size();
      fail(at, processBudget().overBudget((n + 1) * memory_cost::kRayItem,
                                          std::to_string(n + 1) + " objects and materials",
                                          n * memory_cost::kRayItem));
    }
  }
  // Counts a finished mesh's points and triangles against --max-memory.
  void reserveMesh(const Token& at, uint64_t vertices, uint64_t triangles) const {
    uint64_t bytes = vertices * memory_cost::kMeshVertex + triangles * memory_cost::kMeshTriangle;
    if (!processBudget().tryReserve(bytes)) fail(at, processBudget().overBudget(bytes, "meshes"));
  }
  [[noreturn]] void expected(const std::string& what, const Token& got) const {
    fail(got, "expected " + what + ", got " + got.describe());
  }
  std::string where(const Token& t) const {
    return std::to_string(t.line) + ":" + std::to_string(t.column);
  }
  // An unknown attribute or item: an error, or with --lenient a warning and its value skipped.
  void unknown(const Token& key, std::string_view context);
  void skipValue();

  // ---- tokens and values ----------------------------------------------------------------
  Token expectPunct(char c) {
    Token t = lex_.next();
    if (!t.isPunct(c)) expected(quoteChar(c), t);
    return t;
  }
  void expectEquals() { expectPunct('='); }
  Token numberToken() {
    Token t = lex_.next();
    if (t.kind != TokenKind::Number) expected("a number", t);
    return t;
  }
  // Values that round to FLT_MAX are fine; only what would round to infinity is not.
  float toFloat(const Token& t) const {
    if (std::fabs(t.number) >= double(FLT_MAX) + std::ldexp(1.0, 103))
      fail(t, "number " + t.text + " is out of range for a float");
    return float(t.number);
  }
  float floatValue() { return toFloat(numberToken()); }
  // A float that must be >= 0 (or > 0 when `positive`); `what` names it in the message.
  float nonNegative(const char* what, bool positive = false) {
    Token t = numberToken();
    float v = toFloat(t);
    if (positive ? !(v > 0) : !(v >= 0))
      fail(t, std::string(what) + (positive ? " must be > 0" : " must be >= 0") + ", got " + t.text);
    return v;
  }
  uint64_t integerValue(const char* what, uint64_t max, const char* flag = nullptr);
  bool boolValue() {
    Token t = lex_.next();
    if (t.kind != TokenKind::Bool) expected("true or false", t);
    return t.boolean;
  }
  Token nameValue();
  // "(a, b, ...)" with exactly n numbers; `open` receives the '(' token.
  // `bounded`: each number is checked with checkCoordinate.
  void tuple(int n, double* out, bool asFloat, Token* open = nullptr, bool bounded = false);
  Vec3 vec3(Token* open = nullptr) {
    double d[3];
    tuple(3, d, true, open);
    return Vec3(float(d[0]), float(d[1]), float(d[2]));
  }
  // A position, direction or transform entry: |value| <= kMaxCoordinate, so that rays,
  // bounds and transforms stay far from float overflow (Embree refuses rays beyond ~1.8e18).
  static constexpr double kMaxCoordinate = 1e15;
  void checkCoordinate(const Token& t) const {
    if (!(std::fabs(t.number) <= kMaxCoordinate))
      fail(t, "number " + t.text + " is too large for a coordinate (at most 1e15 in magnitude)");
  }
  Vec3 coord(Token* open = nullptr) {
    double d[3];
    tuple(3, d, true, open, true);
    return Vec3(float(d[0]), float(d[1]), float(d[2]));
  }
  // "( item, item, ... )" calling item() for each entry.
  void list(const std::function<void()>& item);
  template <class F>
  void block(std::string_view what, F&& onAttr);

  ColorParam colorValue();
  ScalarParam scalarValue();
  TextureRef mapValue(const Token& mapKeyword);

  // ---- scene items ------------------------------------------------------------------------
  void header();
  int materialValue(int baseIndex);
  int materialBlock(int baseIndex);
  void materialDecl();
  LuminosityDesc luminosity(const Token& key);
  void camera(const Token& kw);
  void ambientLight(const Token& kw);
  void light(const Token& kw);
  void areaLight(const Token& kw);
  void instantRadiosity(const Token& kw);
  void environmentLight(const Token& kw);
  void sunSkyLight(const Token& kw);
  // `lights = n` of environment_light / sun_sky_light: an integer in [1, --max-lights].
  int envLightCount();
  void node();
  bool closeFrames();
  Mat4 transformArgs(const Token& kw);
  void pushFrame(bool group, const Mat4& xf, const Token& open);
  void primitive(const Token& kw);
  void trimesh(const Token& kw, ObjectDesc& obj);
  void objMesh(const Token& kw, ObjectDesc& obj);
  void sphereLight(const Token& kw, ObjectDesc& obj);
  // `emission = (r,g,b)`: reads the value (after the key), components finite and >= 0.
  Color emissionValue();
  // Makes `m` emit radiance `le`: emissive = le (the camera sees it) and a per-area
  // luminosity { colour = le; intensity = 1/pi; per_area; density = --emission-density }.
  void applyEmission(MaterialDesc& m, const Color& le, const Token& at) const;
  // A copy of material `index` (unnamed) with `emission = le` applied; returns its index.
  int emissiveCopy(int index, const Color& le, const Token& at);
  void addLight(LightDesc&& l, const Token& kw);
  void checkMeshLimits(const Token& at, uint64_t vertices, uint64_t triangles) const;

  Mat4 currentTransform() const { return frames_.empty() ? Mat4::identity() : frames_.back().xf; }

  struct Frame {
    bool group;
    Mat4 xf;            // object-to-world for what is inside
    int savedDefault;   // group: the default material to restore at its '}'
    std::string what;   // "translate", ..., "group"
    int line, column;
  };

  RayLexer lex_;
  std::string baseDir_;
  const ParseOptions& opt_;
  SceneDesc scene_;
  int defaultMat_ = 0;                           // index of the current default material
  std::unordered_map<std::string, int> named_;   // declared material names
  std::vector<Frame> frames_;                    // open transforms and groups
  uint64_t totalVertices_ = 0, totalTriangles_ = 0;
  Token cameraToken_;
  // PBR material keys accepted and ignored (type, metallic, roughness, translucency): how
  // often each was seen, and where the first was; one summary warning at the end.
  std::map<std::string, int> ignoredPbr_;
  std::optional<SourceLoc> firstPbr_;
};

// ---------------------------------------------------------------------------------------
// Values

void Parser::tuple(int n, double* out, bool asFloat, Token* openOut, bool bounded) {
  Token open = lex_.next();
  if (!open.isPunct('(')) expected("'('", open);
  int count = 0;
  if (lex_.peek().isPunct(')')) {
    lex_.next();
  } else {
    for (;;) {
      Token t = lex_.next();
      if (t.kind != TokenKind::Number) expected("a number", t);
      if (count < n) out[count] = asFloat ? double(toFloat(t)) : t.number;
      if (bounded) checkCoordinate(t);
      ++count;
      Token sep = lex_.next();
      if (sep.isPunct(')')) break;
      if (!sep.isPunct(',')) expected("',' or ')'", sep);
    }
  }
  if (count != n)
    fail(open, "expected " + std::to_string(n) + " numbers, got " + std::to_string(count));
  if (openOut) *openOut = open;
}

void Parser::list(const std::function<void()>& item) {
  expectPunct('(');
  if (lex_.peek().isPunct(')')) {
    lex_.next();
    return;
  }
  for (;;) {
    item();
    Token sep = lex_.next();
    if (sep.isPunct(')')) return;
    if (!sep.isPunct(',')) expected("',' or ')'", sep);
  }
}

// Integers are re-read from their spelling so that 64-bit seeds keep every bit.
uint64_t Parser::integerValue(const char* what, uint64_t max, const char* flag) {
  Token t = numberToken();
  uint64_t v = 0;
  std::string_view s = t.text;
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  bool digitsOnly = !s.empty() && s.find_first_not_of("0123456789") == std::string_view::npos;
  if (digitsOnly) {
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc()) fail(t, std::string(what) + " " + t.text + " is too large");
  } else if (t.number < 0) {
    fail(t, std::string(what) + " must be >= 0, got " + t.text);
  } else if (std::floor(t.number) != t.number || t.number >= 18446744073709551616.0) {
    expected("an integer for " + std::string(what), t);
  } else {
    v = uint64_t(t.number);
  }
  if (v > max) {
    std::string msg = std::string(what) + " " + t.text + " is more than the limit of " + std::to_string(max);
    if (flag) msg += std::string(" (raise it with ") + flag + ")";
    fail(t, msg);
  }
  return v;
}

// `name x`, `name = x` or `name = "x"` (the keyword is already read). Returns the name token.
Token Parser::nameValue() {
  if (lex_.peek().isPunct('=')) lex_.next();
  Token t = lex_.next();
  if (t.kind != TokenKind::Ident && t.kind != TokenKind::Bool) expected("a name", t);
  return t;
}

// map("file") or map(file): a texture, path relative to the .ray file's directory.
TextureRef Parser::mapValue(const Token& mapKeyword) {
  expectPunct('(');
  Token f = lex_.next();
  if (f.kind != TokenKind::Ident) expected("a file name", f);
  if (f.text.empty()) fail(f, "empty texture file name");
  expectPunct(')');
  TextureRef ref;
  ref.path = resolveRelative(baseDir_, std::string(f.text));
  ref.loc = lex_.loc(mapKeyword);
  ref.srgb = false;  // scalar maps (shininess, index) are values; colour maps are marked below
  return ref;
}

// A colour: (r,g,b) or map("file"). With a map the constant is unused and left 0.
ColorParam Parser::colorValue() {
  const Token& t = lex_.peek();
  if (t.isWord("map")) {
    Token m = lex_.next();
    // An 8-bit colour map is sRGB-encoded: linearised for a display-encoded output (the
    // default), read as value/255 like the course renderer under --tonemap clamp.
    TextureRef ref = mapValue(m);
    ref.srgb = true;
    return ColorParam{Color(0, 0, 0), ref};
  }
  if (t.isPunct('(')) return ColorParam{vec3(), std::nullopt};
  expected("a colour (r,g,b) or map(\"file\")", lex_.next());
}

// A scalar: a number or map("file") (the texture's mean channel).
ScalarParam Parser::scalarValue() {
  const Token& t = lex_.peek();
  if (t.isWord("map")) {
    Token m = lex_.next();
    return ScalarParam{0, mapValue(m)};
  }
  if (t.kind == TokenKind::Number) return ScalarParam{floatValue(), std::nullopt};
  expected("a number or map(\"file\")", lex_.next());
}

// "{ key ... }": calls onAttr(key) for each attribute name; onAttr reads the value and
// returns false for a key it does not know. Semicolons between attributes are optional.
template <class F>
void Parser::block(std::string_view what, F&& onAttr) {
  Token open = lex_.next();
  if (!open.isPunct('{')) expected("'{' after " + what, open);
  for (;;) {
    const Token& t = lex_.peek();
    if (t.isPunct('}')) {
      lex_.next();
      return;
    }
    if (t.isPunct(';')) {
      lex_.next();
      continue;
    }
    if (t.kind == TokenKind::End)
      expected("'}' to close " + what + " opened at " + where(open), t);
    if (t.kind != TokenKind::Ident) expected("an attribute name or '}' in " + what, t);
    Token key = lex_.next();
    if (!onAttr(key)) unknown(key, what);
  }
}

void Parser::unknown(const Token& key, std::string_view context) {
  std::string msg = "unknown keyword " + quoteInput(key.text) + "";
  if (!context.empty()) msg += " in " + context;
  if (!opt_.lenient) fail(key, msg);
  scene_.warnings.push_back(lex_.loc(key).str() + ": warning: " + msg + " (skipped)");
  skipValue();
}

// Skips an unknown attribute's value: tokens up to the next ';' at the same level (eaten),
// the '}' or ')' that closes the enclosing block (kept), or the end of a balanced {...}
// (and a ';' right after it). Parentheses and braces must balance; no recursion.
void Parser::skipValue() {
  struct Open { char closer; Token tok; };
  std::vector<Open> open;
  for (;;) {
    const Token& t = lex_.peek();
    if (t.kind == TokenKind::End) {
      if (open.empty()) return;
      expected(quoteChar(open.back().closer) + " to match " + open.back().tok.describe() +
                   " at " + where(open.back().tok),
               t);
    }
    if (open.empty()) {
      if (t.isPunct(';')) {
        lex_.next();
        return;
      }
      if (t.isPunct('}') || t.isPunct(')')) return;
    }
    Token k = lex_.next();
    if (k.isPunct('(') || k.isPunct('{')) {
      if (int(open.size()) >= opt_.limits.maxNesting)
        fail(k, "nesting deeper than the limit of " + std::to_string(opt_.limits.maxNesting) +
                    " levels (raise it with --max-nesting)");
      open.push_back({k.punct == '(' ? ')' : '}', k});
    } else if (k.isPunct(')') || k.isPunct('}')) {
      if (k.punct != open.back().closer) expected(quoteChar(open.back().closer), k);
      open.pop_back();
      if (open.empty() && k.punct == '}') {
        if (lex_.peek().isPunct(';')) lex_.next();
        return;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Header and top level

// "SBT-raytracer" NUMBER: any version number is accepted (files say 1.0 or 1.1).
void Parser::header() {
  Token h = lex_.next();
  if (h.kind != TokenKind::Ident || h.quoted || h.text != "SBT-raytracer")
    expected("the header 'SBT-raytracer 1.0'", h);
  Token v = lex_.next();
  if (v.kind != TokenKind::Number) expected("a version number after 'SBT-raytracer'", v);
}

// scene := header { item }; item := camera | lights | instant_radiosity | material_decl | node | ";"
SceneDesc Parser::run() {
  header();
  scene_.materials.push_back(MaterialDesc{});  // index 0: the initial default (all 0, index 1)
  Progress progress(opt_.progress, double(lex_.size()));
  size_t reported = 0;
  for (;;) {
    const Token& t = lex_.peek();
    progress.add(double(lex_.offset() - reported));
    reported = lex_.offset();
    if (t.kind == TokenKind::End) break;
    if (t.isPunct(';')) {
      lex_.next();
      continue;
    }
    if (t.isPunct('}')) fail(t, "unexpected '}' (no block is open)");
    if (t.isPunct('{') || isTransformWord(t) || isPrimitiveWord(t)) {
      node();
      continue;
    }
    if (t.kind != TokenKind::Ident) expected("a scene item (camera, light, material or object)", lex_.next());
    const std::string_view w = t.quoted ? std::string_view() : t.word;
    if (w == "material") {
      materialDecl();
      continue;
    }
    Token kw = lex_.next();
    if (w == "camera") camera(kw);
    else if (w == "ambient_light") ambientLight(kw);
    else if (w == "point_light" || w == "directional_light" || w == "spot_light") light(kw);
    else if (w == "area_light") areaLight(kw);
    else if (w == "instant_radiosity") instantRadiosity(kw);
    else if (w == "environment_light") environmentLight(kw);
    else if (w == "sun_sky_light") sunSkyLight(kw);
    else unknown(kw, "");
  }
  if (!ignoredPbr_.empty()) {
    std::string keys;
    for (const auto& [k, n] : ignoredPbr_)
      keys += (keys.empty() ? "" : ", ") + k + (n > 1 ? " (x" + std::to_string(n) + ")" : "");
    scene_.warnings.push_back(firstPbr_->str() + ": warning: PBR material keys ignored (shading is Phong; " +
                              "`albedo` is read as diffuse): " + keys);
  }
  return std::move(scene_);
}

// ---------------------------------------------------------------------------------------
// Materials

// material_decl := "material" "=" material   (top level or in a group)
// Sets the default material that later blocks start from, for the rest of the file or
// of the enclosing group.
void Parser::materialDecl() {
  lex_.next();  // "material"
  expectEquals();
  defaultMat_ = materialValue(defaultMat_);
}

// material := "{" { mat_attr } "}" | IDENT (a declared name). Returns its index.
int Parser::materialValue(int baseIndex) {
  const Token& t = lex_.peek();
  if (t.isPunct('{')) return materialBlock(baseIndex);
  if (t.kind == TokenKind::Ident) {
    Token n = lex_.next();
    auto it = named_.find(std::string(n.text));
    if (it == named_.end()) fail(n, "unknown material " + quoteInput(n.text) + "");
    return it->second;
  }
  expected("a material block '{...}' or a material name", lex_.next());
}

// A material block. Starts as a copy of the material at `baseIndex` (the current default;
// its name is not copied) and overrides what it lists:
//   emissive, ambient, diffuse, specular, reflective, transmissive = (r,g,b) | map("file")
//                           default (0,0,0); `emissive` also sets emissiveSet
//   shininess = s | map()   Phong exponent >= 0, default 0
//   index = s | map()       refractive index > 0, default 1
//   name x | name = "x"     declares the material for later `material = x`
//   luminosity = { ... }    makes objects with this material lights (see luminosity())
//   emission = (r,g,b)      COMP4411: radiance Le; emissive = Le and a per-area luminosity
//                           (see applyEmission())
//   albedo = c              PBR (COMP4411 microfacet): the diffuse colour when the block
//                           sets no `diffuse`
//   type, metallic, roughness, translucency   PBR: accepted, ignored (one summary warning)
int Parser::materialBlock(int baseIndex) {
  checkItemLimit(lex_.peek());
  MaterialDesc m = scene_.materials[size_t(baseIndex)];
  m.name.clear();
  m.loc = lex_.loc(lex_.peek());
  bool haveDiffuse = false;
  std::optional<ColorParam> albedo;
  block("material", [&](const Token& k) {
    const std::string_view w = k.word;
    auto colour = [&](ColorParam& c) {
      expectEquals();
      c = colorValue();
    };
    if (w == "emissive") {
      colour(m.emissive);
      m.emissiveSet = true;
    } else if (w == "ambient") {
      colour(m.ambient);
    } else if (w == "diffuse") {
      colour(m.diffuse);
      haveDiffuse = true;
    } else if (w == "albedo") {
      expectEquals();
      albedo = colorValue();
    } else if (w == "emission") {
      expectEquals();
      applyEmission(m, emissionValue(), k);
    } else if (oneOf(w, {"type", "metallic", "roughness", "translucency"})) {
      ++ignoredPbr_[std::string(w)];
      if (!firstPbr_) firstPbr_ = lex_.loc(k);
      skipValue();
    } else if (w == "specular") {
      colour(m.specular);
    } else if (w == "reflective") {
      colour(m.reflective);
    } else if (w == "transmissive") {
      colour(m.transmissive);
    } else if (w == "shininess" || w == "index") {
      expectEquals();
      Token vt = lex_.peek();
      ScalarParam s = scalarValue();
      if (w == "shininess" && !s.map && !(s.value >= 0))
        fail(vt, "shininess must be >= 0, got " + vt.text);
      if (w == "index" && !s.map && !(s.value > 0)) fail(vt, "index must be > 0, got " + vt.text);
      if (w == "index" && !s.map && !(s.value <= 1000))
        fail(vt, "index must be at most 1000, got " + vt.text);
      (w == "shininess" ? m.shininess : m.index) = s;
    } else if (w == "name") {
      Token at = nameValue();
      const std::string_view n = at.text;
      if (!n.empty()) {
        auto it = named_.find(std::string(n));
        if (it != named_.end())
          fail(at, "material " + quoteInput(n) + " is already declared (at " +
                       scene_.materials[size_t(it->second)].loc.str() + ")");
      }
      m.name = n;
    } else if (w == "luminosity") {
      m.luminosity = luminosity(k);
    } else {
      return false;
    }
    return true;
  });
  if (albedo && !haveDiffuse) m.diffuse = *albedo;
  int index = int(scene_.materials.size());
  if (!m.name.empty()) named_[m.name] = index;
  scene_.materials.push_back(std::move(m));
  return index;
}

// luminosity = { colour|color = (r,g,b) | map("file") | texture;   default (1,1,1)
//                intensity = total power >= 0 (default 1);
//                density = point lights per unit area >= 0 (default 1);
//                per_area = true|false: intensity per unit of world area (default false);
//                constant/linear/quadratic_attenuation_coeff >= 0 (default 0, 0, 1); }
// Starts from these defaults (not from the default material's luminosity).
LuminosityDesc Parser::luminosity(const Token& key) {
  expectEquals();
  LuminosityDesc l;
  l.loc = lex_.loc(key);
  block("luminosity", [&](const Token& k) {
    const std::string_view w = k.word;
    if (!oneOf(w, {"color", "intensity", "density", "per_area", "constant_attenuation_coeff",
                   "linear_attenuation_coeff", "quadratic_attenuation_coeff"}))
      return false;
    expectEquals();
    if (w == "color") {
      if (lex_.peek().isWord("texture")) {
        lex_.next();
        l.colour = ColorParam{Color(1, 1, 1), std::nullopt};
        l.colourFromDiffuse = true;
      } else {
        l.colour = colorValue();
        l.colourFromDiffuse = false;
      }
    } else if (w == "intensity") {
      l.intensity = nonNegative("intensity");
    } else if (w == "density") {
      l.density = nonNegative("density");
    } else if (w == "per_area") {
      l.perArea = boolValue();
    } else if (w == "constant_attenuation_coeff") {
      l.attenConstant = nonNegative("constant_attenuation_coeff");
    } else if (w == "linear_attenuation_coeff") {
      l.attenLinear = nonNegative("linear_attenuation_coeff");
    } else if (w == "quadratic_attenuation_coeff") {
      l.attenQuadratic = nonNegative("quadratic_attenuation_coeff");
    } else {
      return false;
    }
    return true;
  });
  return l;
}

// ---------------------------------------------------------------------------------------
// Camera and lights

// camera { position = (x,y,z)        default (0,0,0)
//          viewdir = (x,y,z)         default (0,0,-1)
//          updir = (x,y,z)           default (0,1,0)
//          look_at = (x,y,z)         viewdir = look_at - position (resolved at the '}')
//          quaternion = (x,y,z,w)    rotates the default frame (-z view, +y up)
//          fov = degrees             vertical, 0 < fov < 180, default 53.13
//          aspectratio = w/h         > 0, default from the image size }
// The last of viewdir / look_at / quaternion decides the view direction.
void Parser::camera(const Token& kw) {
  if (scene_.hasCamera)
    fail(kw, "a second camera (the first is at " + where(cameraToken_) + ")");
  CameraDesc c;
  c.loc = lex_.loc(kw);
  Vec3 lookAt;  // (a plain flag rather than std::optional: GCC warns on optional<Vec3>)
  bool haveLookAt = false;
  Token viewTok = kw, upTok = kw, lookTok;
  block("camera", [&](const Token& k) {
    const std::string_view w = k.word;
    if (!oneOf(w, {"position", "viewdir", "updir", "look_at", "quaternion", "fov", "aspectratio"}))
      return false;
    expectEquals();
    if (w == "position") {
      c.position = coord();
    } else if (w == "viewdir") {
      c.viewDir = coord(&viewTok);
      if (c.viewDir == Vec3(0, 0, 0)) fail(viewTok, "viewdir must not be zero");
      haveLookAt = false;
    } else if (w == "updir") {
      c.upDir = coord(&upTok);
      if (c.upDir == Vec3(0, 0, 0)) fail(upTok, "updir must not be zero");
    } else if (w == "look_at") {
      lookAt = coord(&lookTok);
      haveLookAt = true;
    } else if (w == "quaternion") {
      Token open;
      double q[4];
      tuple(4, q, false, &open);
      double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(n > 0) || !std::isfinite(n)) fail(open, "quaternion must not be zero");
      double x = q[0] / n, y = q[1] / n, z = q[2] / n, qw = q[3] / n;
      // Columns of the rotation matrix: view = R (0,0,-1), up = R (0,1,0).
      c.viewDir = Vec3(float(-2 * (x * z + y * qw)), float(-2 * (y * z - x * qw)),
                       float(-(1 - 2 * (x * x + y * y))));
      c.upDir = Vec3(float(2 * (x * y - z * qw)), float(1 - 2 * (x * x + z * z)),
                     float(2 * (y * z + x * qw)));
      viewTok = upTok = open;
      haveLookAt = false;
    } else if (w == "fov") {
      Token t = numberToken();
      float f = toFloat(t);
      if (!(f > 0 && f < 180)) {
        // Say so when the text is in range but its float is not (179.99999999 is 180.0f).
        std::string got(t.text);
        if (double(f) != t.number) {
          char buf[32];
          std::string fs(buf, std::to_chars(buf, buf + sizeof buf, f).ptr);
          got = fs + " (" + t.text + " rounds to " + fs + " in single precision)";
        }
        fail(t, "fov must be between 0 and 180 degrees, got " + got);
      }
      c.fovDegrees = f;
    } else if (w == "aspectratio") {
      c.aspectRatio = nonNegative("aspectratio", true);
    } else {
      return false;
    }
    return true;
  });
  if (haveLookAt) {
    c.viewDir = lookAt - c.position;
    if (c.viewDir == Vec3(0, 0, 0)) fail(lookTok, "look_at must differ from the camera position");
    viewTok = lookTok;
  }
  // normalizeScaled: the squared length of (1e-30,0,0) underflows a float.
  Vec3 v = normalizeScaled(c.viewDir), u = normalizeScaled(c.upDir);
  if (!(length(cross(v, u)) > 1e-6f)) {
    const Token& at = (upTok.line > viewTok.line ||
                       (upTok.line == viewTok.line && upTok.column > viewTok.column))
                          ? upTok
                          : viewTok;
    fail(at, "viewdir and updir are parallel");
  }
  scene_.camera = c;
  scene_.hasCamera = true;
  cameraToken_ = kw;
}

// ambient_light { colour|color = (r,g,b); }   default (1,1,1); all ambient lights add up.
void Parser::ambientLight(const Token& kw) {
  Color c(1, 1, 1);
  block("ambient_light", [&](const Token& k) {
    if (k.word != "color") return false;
    expectEquals();
    c = vec3();
    return true;
  });
  scene_.ambient += c;
}

void Parser::addLight(LightDesc&& l, const Token& kw) {
  if (scene_.lights.size() >= opt_.limits.maxLights)
    fail(kw, "more lights than the limit of " + std::to_string(opt_.limits.maxLights) +
                 " (raise it with --max-lights)");
  scene_.lights.push_back(std::move(l));
}

// point_light       { position = (0,0,0); colour = (1,1,1); attenuation coefficients }
// directional_light { direction = (0,0,-1) (where the light travels); colour = (1,1,1) }
// spot_light        { position; direction | target = point; colour; attenuation coefficients;
//                     exponent = e >= 0 (default 0): falloff max(0, cos)^e;
//                     cutoff = degrees in (0,180] (default 90): dark beyond;
//                     cone_angle = degrees in (0,180] (half-angle); penumbra = degrees >= 0;
//                     size = full cone angle in degrees (cone_angle = size/2);
//                     blend = 0..1 (penumbra = blend * cone angle, applied at the '}');
//                     cutoff_distance = d > 0: no light beyond d (default infinite) }
// Attenuation: constant/linear/quadratic_attenuation_coeff >= 0, default 0, 0, 1
// (point and spot lights); a light that sets none of the three takes --default-attenuation
// when given. The last of direction / target decides the spot axis.
void Parser::light(const Token& kw) {
  const std::string_view kind = kw.word;
  LightDesc l;
  l.kind = kind == "point_light" ? LightKind::Point
           : kind == "spot_light" ? LightKind::Spot
                                  : LightKind::Directional;
  l.loc = lex_.loc(kw);
  bool positional = l.kind != LightKind::Directional, spot = l.kind == LightKind::Spot;
  Vec3 target;
  bool haveTarget = false;
  std::optional<float> size, blend;
  Token targetTok, blendTok;
  bool anyAtten = false;
  block(kind, [&](const Token& k) {
    const std::string_view w = k.word;
    if (w == "color") {
      expectEquals();
      l.colour = vec3();
    } else if (w == "position" && positional) {
      expectEquals();
      l.position = coord();
    } else if (w == "direction" && (spot || !positional)) {
      expectEquals();
      Token open;
      l.direction = coord(&open);
      if (l.direction == Vec3(0, 0, 0)) fail(open, "direction must not be zero");
      haveTarget = false;
    } else if (w == "target" && spot) {
      expectEquals();
      target = coord(&targetTok);
      haveTarget = true;
    } else if (w == "constant_attenuation_coeff" && positional) {
      expectEquals();
      anyAtten = true;
      l.attenConstant = nonNegative("constant_attenuation_coeff");
    } else if (w == "linear_attenuation_coeff" && positional) {
      expectEquals();
      anyAtten = true;
      l.attenLinear = nonNegative("linear_attenuation_coeff");
    } else if (w == "quadratic_attenuation_coeff" && positional) {
      expectEquals();
      anyAtten = true;
      l.attenQuadratic = nonNegative("quadratic_attenuation_coeff");
    } else if (w == "exponent" && spot) {
      expectEquals();
      l.exponent = nonNegative("exponent");
    } else if ((w == "cutoff" || w == "cone_angle") && spot) {
      expectEquals();
      Token t = numberToken();
      float a = toFloat(t);
      if (!(a > 0 && a <= 180)) fail(t, w + " must be in (0, 180] degrees, got " + t.text);
      if (w == "cutoff") l.cutoffDegrees = a;
      else l.coneAngleDegrees = a;
    } else if (w == "penumbra" && spot) {
      expectEquals();
      l.penumbraDegrees = nonNegative("penumbra");
    } else if (w == "size" && spot) {
      expectEquals();
      Token t = numberToken();
      float s = toFloat(t);
      if (!(s > 0 && s <= 360)) fail(t, "size must be in (0, 360] degrees, got " + t.text);
      size = s;
    } else if (w == "blend" && spot) {
      expectEquals();
      blendTok = numberToken();
      float b = toFloat(blendTok);
      if (!(b >= 0 && b <= 1)) fail(blendTok, "blend must be in [0, 1], got " + blendTok.text);
      blend = b;
    } else if (w == "cutoff_distance" && spot) {
      expectEquals();
      l.cutoffDistance = nonNegative("cutoff_distance", true);
    } else {
      return false;
    }
    return true;
  });
  if (haveTarget) {
    l.direction = target - l.position;
    if (length2(l.direction) == 0) fail(targetTok, "target must differ from the light position");
  }
  if (positional && !anyAtten && opt_.defaultAttenuation) {
    l.attenConstant = (*opt_.defaultAttenuation)[0];
    l.attenLinear = (*opt_.defaultAttenuation)[1];
    l.attenQuadratic = (*opt_.defaultAttenuation)[2];
  }
  if (size) l.coneAngleDegrees = *size / 2;
  if (blend) {
    if (!l.coneAngleDegrees) fail(blendTok, "blend needs size or cone_angle");
    l.penumbraDegrees = *blend * *l.coneAngleDegrees;
  }
  addLight(std::move(l), kw);
}

// area_light { position = corner (default (0,0,0)); u = edge; v = edge (both required);
//              colour|color = (r,g,b) (default (1,1,1)); }
// Becomes a two-triangle mesh object (corner, +u, +u+v, +v) in world space whose material
// is a copy of the current default with diffuse 0 and
// luminosity { colour = the colour; intensity = 1; density = 1 }.
void Parser::areaLight(const Token& kw) {
  checkItemLimit(kw);
  Vec3 corner(0, 0, 0), u, v;
  Color colour(1, 1, 1);
  bool haveU = false, haveV = false;
  block("area_light", [&](const Token& k) {
    const std::string_view w = k.word;
    if (w != "position" && w != "u" && w != "v" && w != "color") return false;
    expectEquals();
    Vec3 x = w == "color" ? vec3() : coord();
    if (w == "position") corner = x;
    else if (w == "u") u = x, haveU = true;
    else if (w == "v") v = x, haveV = true;
    else colour = x;
    return true;
  });
  if (!haveU || !haveV) fail(kw, "area_light needs both u and v");
  {
    // In double: float products of large or tiny edges would overflow or underflow.
    double ux = u.x, uy = u.y, uz = u.z, vx = v.x, vy = v.y, vz = v.z;
    double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
    double area = std::sqrt(cx * cx + cy * cy + cz * cz);
    double lu = std::sqrt(ux * ux + uy * uy + uz * uz), lv = std::sqrt(vx * vx + vy * vy + vz * vz);
    if (!(area > 1e-6 * lu * lv)) fail(kw, "area_light has zero area (u and v are parallel or zero)");
    if (!isFinite(corner + u) || !isFinite(corner + v) || !isFinite(corner + u + v))
      fail(kw, "area_light corners are out of range for a float");
  }
  checkMeshLimits(kw, 4, 2);
  MeshDesc mesh;
  mesh.points = {corner, corner + u, corner + u + v, corner + v};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  reserveMesh(kw, 4, 2);
  totalVertices_ += 4;
  totalTriangles_ += 2;

  MaterialDesc m = scene_.materials[size_t(defaultMat_)];
  m.name.clear();
  m.diffuse = ColorParam{};
  LuminosityDesc lum;
  lum.colour = ColorParam{colour, std::nullopt};
  lum.intensity = 1;
  lum.loc = lex_.loc(kw);
  // The course renderers took the attenuation from their UI for every light: an area light
  // sets no coefficients, so --default-attenuation (the sliders) applies to it too.
  if (opt_.defaultAttenuation) {
    lum.attenConstant = (*opt_.defaultAttenuation)[0];
    lum.attenLinear = (*opt_.defaultAttenuation)[1];
    lum.attenQuadratic = (*opt_.defaultAttenuation)[2];
  }
  m.luminosity = lum;
  m.loc = lex_.loc(kw);

  ObjectDesc obj;
  obj.kind = ShapeKind::Mesh;
  obj.material = int(scene_.materials.size());
  scene_.materials.push_back(std::move(m));
  obj.mesh = int(scene_.meshes.size());
  scene_.meshes.push_back(std::move(mesh));
  obj.loc = lex_.loc(kw);
  obj.twoSidedEmission = true;
  scene_.objects.push_back(std::move(obj));
}

// instant_radiosity { vpls = n >= 0 (at most --max-vpls); bounces = n >= 0;
//                     normalize = "power" | "object"; clamp = c >= 0; seed = 64-bit integer;
//                     caustics = n >= 0; caustic_lights = "vpl" | "spot"; }
// Every field is optional; command-line flags override. A second block updates the first.
// The names of normalize and caustic_lights are their enums' (kVplNormalizeNames,
// kCausticLightKindNames in scene_desc.h).
void Parser::instantRadiosity(const Token& kw) {
  InstantRadiosityDesc ir = scene_.instantRadiosity.value_or(InstantRadiosityDesc{});
  ir.loc = lex_.loc(kw);
  block("instant_radiosity", [&](const Token& k) {
    const std::string_view w = k.word;
    if (!oneOf(w, {"vpls", "bounces", "normalize", "clamp", "seed", "caustics", "caustic_lights"})) return false;
    expectEquals();
    if (w == "vpls") {
      ir.vpls = int(integerValue("vpls", std::min<uint64_t>(opt_.limits.maxVpls, INT32_MAX),
                                 "--max-vpls"));
    } else if (w == "bounces") {
      ir.bounces = int(integerValue("bounces", 1000));
    } else if (w == "normalize") {
      Token t = lex_.next();
      std::optional<VplNormalize> v = t.kind == TokenKind::Ident ? findEnum(kVplNormalizeNames, t.text) : std::nullopt;
      if (!v) expected(enumChoices(kVplNormalizeNames, "\"") + " for normalize", t);
      ir.normalize = *v;
    } else if (w == "clamp") {
      ir.clamp = nonNegative("clamp");
    } else if (w == "seed") {
      ir.seed = integerValue("seed", UINT64_MAX);
    } else if (w == "caustics") {
      ir.caustics = int(integerValue("caustics", INT32_MAX));
    } else if (w == "caustic_lights") {
      Token t = lex_.next();
      std::optional<CausticLightKind> k =
          t.kind == TokenKind::Ident ? findEnum(kCausticLightKindNames, t.text) : std::nullopt;
      if (!k) expected(enumChoices(kCausticLightKindNames, "\"") + " for caustic_lights", t);
      ir.causticLights = *k;
    } else {
      return false;
    }
    return true;
  });
  scene_.instantRadiosity = ir;
}

int Parser::envLightCount() {
  Token t = lex_.peek();
  uint64_t n = integerValue("lights", std::min<uint64_t>(opt_.limits.maxLights, INT32_MAX), "--max-lights");
  if (n == 0) fail(t, "lights must be >= 1, got 0");
  return int(n);
}

// environment_light {
//   map = "sky.hdr";     optional equirectangular map (.hdr, .exr or an 8-bit image stb reads,
//                        sRGB-decoded): linear radiance; relative to the .ray file's directory
//   colour = (r,g,b);    >= 0, multiplies the map; without a map a uniform environment; (1,1,1)
//   intensity = s;       >= 0, scale; default 1
//   up = (x,y,z);        the map's zenith, not zero; default (0,1,0)
//   rotate = degrees;    about up (right-handed); default 0
//   lights = n;          directional lights it becomes, >= 1; default 4096 (--env-lights overrides)
//   visible = true;      seen by camera, reflected and refracted rays that miss everything
// }
// Radiance convention: a diffuse surface of albedo kd under a uniform environment of
// radiance L, unoccluded, renders as kd * L (pbrt's). See docs/SCENE_FORMAT.md.
void Parser::environmentLight(const Token& kw) {
  EnvironmentDesc e;
  e.kind = EnvironmentKind::Map;
  e.loc = lex_.loc(kw);
  block("environment_light", [&](const Token& k) {
    const std::string_view w = k.word;
    if (!oneOf(w, {"map", "color", "intensity", "up", "rotate", "lights", "visible"})) return false;
    expectEquals();
    if (w == "map") {
      Token f = lex_.next();
      if (f.kind != TokenKind::Ident) expected("a file name (\"sky.hdr\")", f);
      if (f.text.empty()) fail(f, "empty environment map file name");
      TextureRef ref;
      ref.path = resolveRelative(baseDir_, std::string(f.text));
      ref.loc = lex_.loc(f);
      ref.srgb = true;  // 8-bit maps are sRGB-encoded; .hdr and .exr stay linear
      e.map = ref;
    } else if (w == "color") {
      Token open;
      e.colour = vec3(&open);
      if (!(e.colour.x >= 0 && e.colour.y >= 0 && e.colour.z >= 0))
        fail(open, "environment_light colour must be >= 0 in every component");
    } else if (w == "intensity") {
      e.intensity = nonNegative("intensity");
    } else if (w == "up") {
      Token open;
      e.up = coord(&open);
      if (e.up.x == 0 && e.up.y == 0 && e.up.z == 0) fail(open, "up must not be zero");
    } else if (w == "rotate") {
      e.rotateDegrees = floatValue();
    } else if (w == "lights") {
      e.lights = envLightCount();
    } else {
      e.visible = boolValue();
    }
    return true;
  });
  scene_.environments.push_back(std::move(e));
}

// sun_sky_light {
//   direction = (x,y,z); the direction sunlight travels (as directional_light), y up; the sun
//                        must be above the horizon (y < 0); default (0,-1,0)
//   turbidity = t;       Preetham et al. 1999's atmospheric turbidity, in [2, 10]; default 3
//   intensity = s;       >= 0; at 1 the sun and sky together light a white horizontal diffuse
//                        surface to 1; default 1
//   lights = n;          directional lights for the sky, >= 1 (the sun is one more); default 4096
//   ground = (r,g,b);    >= 0: radiance below the horizon is ground * intensity (a ground of
//                        that albedo under the same sun and sky); default (0,0,0)
//   visible = true;      the sky (and sun disk) seen by rays that miss everything
// }
void Parser::sunSkyLight(const Token& kw) {
  EnvironmentDesc e;
  e.kind = EnvironmentKind::SunSky;
  e.loc = lex_.loc(kw);
  block("sun_sky_light", [&](const Token& k) {
    const std::string_view w = k.word;
    if (!oneOf(w, {"direction", "turbidity", "intensity", "lights", "ground", "visible"})) return false;
    expectEquals();
    if (w == "direction") {
      Token open;
      e.sunDirection = coord(&open);
      Vec3d d(e.sunDirection);
      double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
      if (len == 0) fail(open, "direction must not be zero");
      if (!(d.y < -1e-6 * len))
        fail(open, "the sun must be above the horizon: direction (where sunlight travels) needs y < 0");
    } else if (w == "turbidity") {
      Token t = numberToken();
      e.turbidity = toFloat(t);
      if (!(e.turbidity >= 2 && e.turbidity <= 10))
        fail(t, "turbidity must be in [2, 10] (the range of Preetham's model), got " + t.text);
    } else if (w == "intensity") {
      e.intensity = nonNegative("intensity");
    } else if (w == "lights") {
      e.lights = envLightCount();
    } else if (w == "ground") {
      Token open;
      e.ground = vec3(&open);
      if (!(e.ground.x >= 0 && e.ground.y >= 0 && e.ground.z >= 0))
        fail(open, "ground must be >= 0 in every component");
    } else {
      e.visible = boolValue();
    }
    return true;
  });
  scene_.environments.push_back(std::move(e));
}

// ---------------------------------------------------------------------------------------
// Nodes: transforms, groups and primitives

void Parser::pushFrame(bool group, const Mat4& xf, const Token& open) {
  if (int(frames_.size()) >= opt_.limits.maxNesting)
    fail(open, "nesting deeper than the limit of " + std::to_string(opt_.limits.maxNesting) +
                   " levels (raise it with --max-nesting)");
  frames_.push_back(Frame{group, xf, defaultMat_, group ? std::string("group") : std::string(open.text), open.line, open.column});
}

// node := primitive | transform | "{" { node | material_decl | ";" } "}"
// Descends through transforms and groups by pushing frames; closeFrames() then consumes
// the ')' and '}' that follow a finished node.
void Parser::node() {
  for (;;) {
    Token t = lex_.next();
    if (isTransformWord(t)) {
      Mat4 m = transformArgs(t);
      Mat4 xf = currentTransform() * m;
      // Each argument is at most 1e15 (checkCoordinate); nesting can still multiply them up.
      bool tooLarge = !xf.isFinite();
      for (const auto& row : xf.m)
        for (double v : row) tooLarge = tooLarge || !(std::fabs(v) <= 1e30);
      if (tooLarge) fail(t, "transform overflows (an entry of the accumulated matrix exceeds 1e30)");
      pushFrame(false, xf, t);
      continue;  // its child node follows
    }
    if (t.isPunct('{')) {
      pushFrame(true, currentTransform(), t);
    } else if (isPrimitiveWord(t)) {
      primitive(t);
    } else if (t.kind == TokenKind::Ident && !isTopLevelOnlyWord(t) && t.word != "material") {
      unknown(t, "");  // lenient: the unknown object is skipped
    } else {
      expected("a primitive, transform or '{'", t);
    }
    if (!closeFrames()) return;
  }
}

// Called after a complete node (or a '{'). Closes finished transforms with ')' and reads
// the items of the innermost open group. Returns true when that group continues with
// another node, false when the outermost node is complete.
bool Parser::closeFrames() {
  while (!frames_.empty()) {
    Frame& f = frames_.back();
    if (!f.group) {
      Token c = lex_.next();
      if (!c.isPunct(')'))
        expected("')' to close " + f.what + " opened at " + std::to_string(f.line) + ":" +
                     std::to_string(f.column),
                 c);
      frames_.pop_back();
      continue;
    }
    for (;;) {
      const Token& t = lex_.peek();
      if (t.isPunct(';')) {
        lex_.next();
      } else if (t.isWord("material")) {
        materialDecl();  // the group's default, until its '}'
      } else if (t.isPunct('}')) {
        lex_.next();
        defaultMat_ = f.savedDefault;
        frames_.pop_back();
        break;
      } else if (t.kind == TokenKind::End) {
        expected("'}' to close the group opened at " + std::to_string(f.line) + ":" +
                     std::to_string(f.column),
                 t);
      } else {
        return true;
      }
    }
  }
  return false;
}

// transform := "translate" "(" x "," y "," z ","
//            | "rotate" "(" ax "," ay "," az "," radians ","     axis normalised, not zero
//            | "scale" "(" s ","  |  "scale" "(" sx "," sy "," sz ","   factors not zero
//            | "transform" "(" row "," row "," row "," row ","   4x4 row-major, last row 0 0 0 1
// followed by the child node and ")". Reads up to and including the ',' before the child.
Mat4 Parser::transformArgs(const Token& kw) {
  const std::string_view w = kw.word;
  expectPunct('(');
  auto arg = [&](Token* tok = nullptr) {
    Token t = numberToken();
    checkCoordinate(t);
    expectPunct(',');
    if (tok) *tok = t;
    return t.number;
  };
  if (w == "translate") {
    double x = arg(), y = arg(), z = arg();
    return Mat4::translate(x, y, z);
  }
  if (w == "rotate") {
    Token axisTok;
    double ax = arg(&axisTok), ay = arg(), az = arg(), angle = arg();
    double len = std::sqrt(ax * ax + ay * ay + az * az);
    if (!(len > 0) || !std::isfinite(len)) fail(axisTok, "rotate axis must not be zero");
    return Mat4::rotate(ax / len, ay / len, az / len, angle);
  }
  if (w == "scale") {
    Token t[3];
    double s[3];
    s[0] = arg(&t[0]);
    if (lex_.peek().kind == TokenKind::Number) {
      s[1] = arg(&t[1]);
      s[2] = arg(&t[2]);
    } else {
      s[1] = s[2] = s[0];
      t[1] = t[2] = t[0];
    }
    for (int i = 0; i < 3; ++i)
      if (s[i] == 0) fail(t[i], "scale factor must not be zero (the transform would be singular)");
    return Mat4::scale(s[0], s[1], s[2]);
  }
  // "transform": four rows of four numbers
  Mat4 m;
  Token rowTok[4];
  for (int r = 0; r < 4; ++r) {
    double row[4];
    tuple(4, row, false, &rowTok[r], true);
    for (int c = 0; c < 4; ++c) m.m[size_t(r)][size_t(c)] = row[c];
    expectPunct(',');
  }
  if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1)
    fail(rowTok[3], "the last row of a transform must be (0,0,0,1)");
  if (m.det3() == 0) fail(kw, "transform matrix is singular");
  return m;
}

// Every primitive: material = {...} | name;  name = x (kept in ObjectDesc::name).
//   sphere    radius 1 at the origin
//   box       the cube [-0.5,0.5]^3
//   square    [-0.5,0.5]^2 in z = 0, normal +z
//   cylinder  radius 1 about z, z in [0,1]; capped = true|false (default true)
//   cone      along +z: height > 0 (1), bottom_radius >= 0 (1), top_radius >= 0 (0),
//             capped (true); the radii must not both be 0
//   trimesh / polymesh, obj_mesh, sphere_light: see trimesh(), objMesh(), sphereLight()
//   emission = (r,g,b)  COMP4411: radiance Le; the object gets a copy of its material with
//             emission applied (see applyEmission())
void Parser::primitive(const Token& kw) {
  checkItemLimit(kw);
  ObjectDesc obj;
  obj.transform = currentTransform();
  obj.material = defaultMat_;
  obj.loc = lex_.loc(kw);
  const std::string_view w = kw.word;
  if (w == "trimesh") return trimesh(kw, obj);
  if (w == "obj_mesh") return objMesh(kw, obj);
  if (w == "sphere_light") return sphereLight(kw, obj);
  obj.kind = w == "sphere" ? ShapeKind::Sphere
             : w == "box"      ? ShapeKind::Box
             : w == "square"   ? ShapeKind::Square
             : w == "cylinder" ? ShapeKind::Cylinder
                               : ShapeKind::Cone;
  bool cyl = obj.kind == ShapeKind::Cylinder, cone = obj.kind == ShapeKind::Cone;
  std::optional<Color> emission;
  Token emissionTok;
  block(kw.text, [&](const Token& k) {
    const std::string_view a = k.word;
    if (a == "material") {
      expectEquals();
      obj.material = materialValue(defaultMat_);
    } else if (a == "emission") {
      expectEquals();
      emissionTok = k;
      emission = emissionValue();
    } else if (a == "name") {
      obj.name = nameValue().text;
    } else if (a == "capped" && (cyl || cone)) {
      expectEquals();
      obj.capped = boolValue();
    } else if (a == "height" && cone) {
      expectEquals();
      obj.height = nonNegative("height", true);
    } else if (a == "bottom_radius" && cone) {
      expectEquals();
      obj.bottomRadius = nonNegative("bottom_radius");
    } else if (a == "top_radius" && cone) {
      expectEquals();
      obj.topRadius = nonNegative("top_radius");
    } else {
      return false;
    }
    return true;
  });
  if (cone && obj.bottomRadius == 0 && obj.topRadius == 0)
    fail(kw, "cone has bottom_radius and top_radius both 0");
  if (emission) obj.material = emissiveCopy(obj.material, *emission, emissionTok);
  scene_.objects.push_back(std::move(obj));
}

Color Parser::emissionValue() {
  Token open;
  Vec3 v = vec3(&open);
  for (int i = 0; i < 3; ++i)
    if (!(v[i] >= 0) || !std::isfinite(v[i]))
      fail(open, "emission components must be finite and >= 0");
  return v;
}

void Parser::applyEmission(MaterialDesc& m, const Color& le, const Token& at) const {
  m.emissive = ColorParam{le, std::nullopt};
  m.emissiveSet = true;
  if (!(std::max({le.x, le.y, le.z}) > 0)) {
    m.luminosity.reset();  // emission = (0,0,0): not a light
    return;
  }
  LuminosityDesc l;
  l.colour = ColorParam{le, std::nullopt};
  // Total intensity A Le / pi: this renderer's diffuse term has no 1/pi (kd I cos / d^2), so
  // a lit surface comes out as bright as under a path tracer's kd / pi (docs/SCENE_FORMAT.md).
  l.intensity = float(1 / 3.14159265358979323846);
  l.perArea = true;
  l.density = opt_.emissionDensity;
  l.loc = lex_.loc(at);
  m.luminosity = l;
}

int Parser::emissiveCopy(int index, const Color& le, const Token& at) {
  checkItemLimit(at);
  MaterialDesc m = scene_.materials[size_t(index)];
  m.name.clear();
  applyEmission(m, le, at);
  scene_.materials.push_back(std::move(m));
  return int(scene_.materials.size()) - 1;
}

// sphere_light { emission = (r,g,b) (required); radius = r > 0 (default 1); name = x; }
// (COMP4411): a sphere of radius r at the origin of the current transform, as COMP4411's
// SphereLight (a unit Sphere under the transform). Its material is the all-black initial
// material with `emission` applied, so it is an object light of radiance Le that the camera
// sees at Le.
void Parser::sphereLight(const Token& kw, ObjectDesc& obj) {
  std::optional<Color> emission;
  Token emissionTok;
  float radius = 1;
  Token radiusTok = kw;
  block("sphere_light", [&](const Token& k) {
    const std::string_view a = k.word;
    if (a == "emission") {
      expectEquals();
      emissionTok = k;
      emission = emissionValue();
    } else if (a == "radius") {
      expectEquals();
      radiusTok = lex_.peek();
      radius = nonNegative("radius", true);
    } else if (a == "name") {
      obj.name = nameValue().text;
    } else {
      return false;
    }
    return true;
  });
  if (!emission) fail(kw, "sphere_light needs emission = (r, g, b)");
  if (radius != 1) {
    obj.transform = obj.transform * Mat4::scale(radius, radius, radius);
    if (!obj.transform.isFinite()) fail(radiusTok, "sphere_light radius overflows the transform");
  }
  obj.kind = ShapeKind::Sphere;
  checkItemLimit(kw);
  MaterialDesc m;
  m.loc = lex_.loc(kw);
  applyEmission(m, *emission, emissionTok);
  obj.material = int(scene_.materials.size());
  scene_.materials.push_back(std::move(m));
  scene_.objects.push_back(std::move(obj));
}

void Parser::checkMeshLimits(const Token& at, uint64_t vertices, uint64_t triangles) const {
  if (totalVertices_ + vertices > opt_.limits.maxVertices)
    fail(at, "more vertices than the limit of " + std::to_string(opt_.limits.maxVertices) +
                 " (raise it with --max-triangles)");
  if (totalTriangles_ + triangles > opt_.limits.maxTriangles)
    fail(at, "more triangles than the limit of " + std::to_string(opt_.limits.maxTriangles) +
                 " (raise it with --max-triangles)");
  // Checked as the mesh grows, counted (reserveMesh) once it is complete.
  uint64_t bytes = vertices * memory_cost::kMeshVertex + triangles * memory_cost::kMeshTriangle;
  if (!processBudget().fits(bytes)) fail(at, processBudget().overBudget(bytes, "meshes"));
}

// trimesh | polymesh {
//   points = ((x,y,z), ...);        the vertices
//   faces = ((i,j,k[,l...]), ...);  0-based; polygons become triangle fans (i,j,k),(i,k,l),...
//   normals = ((x,y,z), ...);       one per point
//   texture_uv | texcoords | tex_coords = ((u,v), ...);   one per point
//   materials = ({...} | name, ...);   one per point; each block starts from the default
//   gennormals; | gennormals = true|false;   compute smooth vertex normals
//   material = ...; name = ...;
//   emission = (r,g,b);   COMP4411: radiance Le; the mesh gets a copy of its material with
//                         emission applied (see applyEmission()) }
// Each list may be given once; semicolons after lists are optional. Face indices are
// checked against the point count (when faces come first, at the '}').
void Parser::trimesh(const Token& kw, ObjectDesc& obj) {
  MeshDesc mesh;
  bool seen[5] = {false, false, false, false, false};  // points faces normals uvs materials
  Token listTok[5];
  struct Pos { int line, column; };
  std::vector<Pos> deferred;  // index positions when faces precede points
  bool pointsDone = false;
  auto once = [&](int i, const Token& k) {
    if (seen[i]) fail(k, quoteInput(k.text) + " is given twice in " + kw.text);
    seen[i] = true;
    listTok[i] = k;
    expectEquals();
  };
  auto outOfRange = [&](long long idx, int line, int column) {
    throw Error(lex_.loc(line, column), "face index " + std::to_string(idx) + " is out of range (the mesh has " +
             std::to_string(mesh.points.size()) + " points)");
  };

  std::optional<Color> emission;
  Token emissionTok;
  block(kw.text, [&](const Token& k) {
    const std::string_view a = k.word;
    if (a == "material") {
      expectEquals();
      obj.material = materialValue(defaultMat_);
    } else if (a == "emission") {
      expectEquals();
      emissionTok = k;
      emission = emissionValue();
    } else if (a == "name") {
      obj.name = nameValue().text;
    } else if (a == "gennormals") {
      mesh.genNormals = true;
      if (lex_.peek().isPunct('=')) {
        lex_.next();
        mesh.genNormals = boolValue();
      }
    } else if (a == "points") {
      once(0, k);
      list([&] {
        Token open = lex_.peek();
        checkMeshLimits(open, mesh.points.size() + 1, 0);
        mesh.points.push_back(vec3());  // not bounded: OBJ vertices are not either (obj2ray)
      });
      pointsDone = true;
    } else if (a == "faces") {
      once(1, k);
      std::vector<long long> poly;
      std::vector<Pos> polyPos;
      list([&] {
        poly.clear();
        polyPos.clear();
        Token open = lex_.peek();
        list([&] {
          Token t = numberToken();
          if (std::floor(t.number) != t.number) fail(t, "face index " + t.text + " is not an integer");
          if (std::fabs(t.number) > 2147483647.0)
            fail(t, "face index " + t.text + " is out of range (" +
                        (pointsDone ? "the mesh has " + std::to_string(mesh.points.size()) + " points"
                                    : std::string("indices are at most 2147483647")) +
                        ")");
          long long idx = (long long)t.number;
          if (pointsDone && (idx < 0 || idx >= (long long)mesh.points.size()))
            outOfRange(idx, t.line, t.column);
          poly.push_back(idx);
          polyPos.push_back({t.line, t.column});
        });
        if (poly.size() < 3)
          fail(open, "a face needs at least 3 indices, got " + std::to_string(poly.size()));
        checkMeshLimits(open, 0, mesh.triangles.size() + poly.size() - 2);
        for (size_t i = 1; i + 1 < poly.size(); ++i) {
          mesh.triangles.push_back({int(poly[0]), int(poly[i]), int(poly[i + 1])});
          if (!pointsDone) {
            deferred.push_back(polyPos[0]);
            deferred.push_back(polyPos[i]);
            deferred.push_back(polyPos[i + 1]);
          }
        }
      });
    } else if (a == "normals") {
      once(2, k);
      list([&] { mesh.normals.push_back(vec3()); });
    } else if (a == "texture_uv") {
      once(3, k);
      list([&] {
        double uv[2];
        tuple(2, uv, true);
        mesh.uvs.push_back(Vec2(float(uv[0]), float(uv[1])));
      });
    } else if (a == "materials") {
      once(4, k);
      list([&] { mesh.vertexMaterials.push_back(materialValue(defaultMat_)); });
    } else {
      return false;
    }
    return true;
  });

  if (mesh.points.empty() || mesh.triangles.empty()) fail(kw, kw.text + " needs points and faces");
  // Faces read before the points are checked now, at each index's own position.
  for (size_t i = 0; i < deferred.size(); ++i) {
    int idx = mesh.triangles[i / 3][i % 3];
    if (idx < 0 || size_t(idx) >= mesh.points.size()) outOfRange(idx, deferred[i].line, deferred[i].column);
  }
  auto perVertex = [&](int i, size_t n) {
    if (seen[i] && n != mesh.points.size())
      fail(listTok[i], kw.text + " has " + std::to_string(mesh.points.size()) + " points but " +
                           std::to_string(n) + " " + listTok[i].text);
  };
  perVertex(2, mesh.normals.size());
  perVertex(3, mesh.uvs.size());
  perVertex(4, mesh.vertexMaterials.size());

  if (emission) obj.material = emissiveCopy(obj.material, *emission, emissionTok);
  reserveMesh(kw, mesh.points.size(), mesh.triangles.size());
  totalVertices_ += mesh.points.size();
  totalTriangles_ += mesh.triangles.size();
  obj.kind = ShapeKind::Mesh;
  obj.mesh = int(scene_.meshes.size());
  scene_.meshes.push_back(std::move(mesh));
  scene_.objects.push_back(std::move(obj));
}

// obj_mesh { file = "model.obj" (required, relative to the .ray file);
//            material = ... (overrides the MTL materials); name = ...;
//            emission = (r,g,b) (COMP4411: the mesh takes a copy of its material, the given
//            one or else the current default, with emission applied; overrides the MTL) }
// The OBJ's MTL materials start from the current default material.
void Parser::objMesh(const Token& kw, ObjectDesc& obj) {
  std::string file;
  std::optional<int> material;
  std::optional<Color> emission;
  Token emissionTok;
  block("obj_mesh", [&](const Token& k) {
    const std::string_view a = k.word;
    if (a == "file") {
      expectEquals();
      Token f = lex_.next();
      if (f.kind != TokenKind::Ident) expected("a file name", f);
      if (f.text.empty()) fail(f, "empty file name");
      file = f.text;
    } else if (a == "material") {
      expectEquals();
      material = materialValue(defaultMat_);
    } else if (a == "emission") {
      expectEquals();
      emissionTok = k;
      emission = emissionValue();
    } else if (a == "name") {
      obj.name = nameValue().text;
    } else {
      return false;
    }
    return true;
  });
  if (file.empty()) fail(kw, "obj_mesh needs a file");
  if (emission) material = emissiveCopy(material ? *material : defaultMat_, *emission, emissionTok);
  Limits remaining = opt_.limits;
  remaining.maxTriangles -= std::min(remaining.maxTriangles, totalTriangles_);
  remaining.maxVertices -= std::min(remaining.maxVertices, totalVertices_);
  ObjData data = loadObj(resolveRelative(baseDir_, file), lex_.loc(kw),
                         scene_.materials[size_t(defaultMat_)], remaining);
  checkMeshLimits(kw, data.mesh.points.size(), data.mesh.triangles.size());
  reserveMesh(kw, data.mesh.points.size(), data.mesh.triangles.size());
  totalVertices_ += data.mesh.points.size();
  totalTriangles_ += data.mesh.triangles.size();
  detail::appendObjMesh(scene_, std::move(data), std::move(obj), material, defaultMat_);
}

}  // namespace

SceneDesc parseRayString(std::string_view text, const std::string& name, const std::string& baseDir,
                         const ParseOptions& options) {
  if (text.size() > options.limits.maxFileBytes)
    throw Error(quoteInput(name) + " is larger than the limit of " + std::to_string(options.limits.maxFileBytes) +
                " bytes");
  Parser parser(text, name, baseDir, options);
  return parser.run();
}

SceneDesc parseRayFile(const std::string& path, const ParseOptions& options) {
  namespace fs = std::filesystem;
  const uint64_t limit = options.limits.maxFileBytes;
  auto tooLarge = [&] {
    return Error(quoteInput(path) + " is larger than the limit of " + std::to_string(limit) + " bytes");
  };
  std::error_code ec;
  fs::file_status st = fs::status(path, ec);
  std::string text;
  if (!ec && st.type() == fs::file_type::fifo) {
    // A pipe (render <(generator) or /dev/stdin): read it up to the size limit.
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error("cannot open " + quoteInput(path) + ": " + std::strerror(errno));
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
      text.append(buf, n);
      if (text.size() > limit) {
        std::fclose(f);
        throw tooLarge();
      }
    }
    std::fclose(f);
  } else {
    // Devices and sockets could block or never end (/dev/zero).
    if (!ec && fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st))
      throw Error("cannot read " + quoteInput(path) + ": not a regular file");
    auto size = fs::file_size(path, ec);
    if (!ec && size > limit) throw tooLarge();
    const BigVector<char> bytes = readFileBytes(path);
    return parseRayString(std::string_view(bytes.data(), bytes.size()), path, parentDir(path), options);
  }
  return parseRayString(text, path, parentDir(path), options);
}

}  // namespace lc::io
