// OBJ/MTL input through tinyobjloader, and obj2ray.
//
// Parsing is tinyobjloader's (v1 LoadObj on the file text, triangulate = true: quads are
// split along their shorter diagonal, larger polygons by ear clipping). We use LoadObj
// with our own MaterialReader rather than ObjReader because ObjReader cannot fall back to
// an MTL beside the .obj when `mtllib` names a path that does not exist (exporters often
// write repo- or machine-relative paths there).
//
// Before tinyobj runs, a light scan of the OBJ text (scanObj) counts v/vt/vn lines and
// face corners, so that
//   - the --max-triangles limits are checked before any large array is built,
//   - out-of-range and zero indices are errors with a line number (tinyobj only warns,
//     at the last line, and silently drops such quads),
//   - non-finite coordinates (nan, inf, 1e999) are errors with a line number (tinyobj
//     reads "nan" as 0 and lets overflow through as inf),
//   - a face of more than 4096 corners is an error with its line number (tinyobj's ear
//     clipping is quadratic: one face of 200,000 corners took minutes).
// A similar scan of each MTL (scanMtl) records which keywords each material lists, so
// that a material overrides only what its MTL block says (tinyobj fills in defaults)
// and so that textures carry the line they were named on.
//
// Mesh: one vertex per distinct (v, vt, vn) tuple used by a face, in first-use order.
// Normals are kept only when every used corner has a vn, uvs only when every used corner
// has a vt; otherwise that attribute is dropped for the whole mesh (and left out of the
// dedupe key). Without normals, genNormals stays false: flat shading, as the file says.
//
// MTL keywords (each material starts as a copy of `base`; only keywords present override):
//   newmtl NAME   material name (MaterialDesc::name); its line is MaterialDesc::loc
//   Kd r g b      diffuse
//   Ks r g b      specular
//   Ka r g b      ambient
//   Ke r g b      emissive = Ke and emissiveSet = true (so a luminous surface shows its
//                 own radiance); when max(Ke) > 0 also a luminosity, see below.
//                 A Ke with all components <= 0 removes a luminosity inherited from `base`.
//   Ns s          shininess (used directly as the Phong exponent, like .ray files)
//   Ni s          index of refraction
//   d s / Tr s    dissolve: transmissive = (1 - d) grey; Tr means 1 - d; `d` wins when a
//                 block has both (tinyobj's rule)
//   map_Kd FILE   diffuse texture        } options (-s, -o, -bm, -clamp, ...) are parsed
//   map_Ke FILE   luminosity colour map  } by tinyobj and ignored; the file name may hold
//                                          spaces and Windows '\' separators
//   Everything else (illum, Tf/Kt, map_Ks, map_Bump/bump, map_d, PBR keys) is ignored.
// Texture paths resolve against the MTL's directory; a file that is not there is looked
// for by its base name beside the MTL, and when that fails too the map is dropped with a
// warning (the constant colour stays), since OBJ packs in the wild often lack textures.
// MTL textures are 8-bit sRGB colour maps: TextureRef::srgb = true.
//
// Ke -> luminosity (the object-light extension; point lights with 1/d^2 attenuation):
//   colour    = Ke / max(Ke)                 (map_Ke, when present, as its texture)
//   intensity = max(Ke) * A                  A = total area of the faces using the
//                                            material, in the OBJ's units
//   density   = 1000 / A                     about 1000 point lights per luminous material
// A Lambertian emitter of radiance L and area A has radiant intensity L*A along its
// normal, so point lights summing to L*A give it the right irradiance at a distance
// (the Phong shading of the course renderer has no 1/pi in its diffuse term; multiplying
// by pi, the emitter's flux, would light the scene pi times too bright). For the McGuire
// Cornell box (Ke 17 12 4 on 0.47 x 0.38) this is intensity 3.04, and the floor under
// the light gets about kd * 0.78 in red. With map_Ke and no positive Ke the scale is 1.
// A is measured in the OBJ's own frame: a .ray that scales an obj_mesh with Ke should
// give it an explicit material.
//
// Default camera and lights (loadObjScene): see defaultCamera / defaultLights below.
#include "io/obj_loader.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "core/file_util.h"
#include "core/memory_budget.h"
#include "io/ray_writer.h"

namespace fs = std::filesystem;

namespace lc::io {
namespace {

// ---------------------------------------------------------------------------------------
// Text helpers

// Calls fn(lineNumber, line) for each line, splitting like tinyobj's safeGetline ("\n",
// "\r\n" or a lone "\r") so line numbers agree with tinyobj's messages. A NUL ends the
// line's content, as it does for tinyobj (which works on c_str()).
template <class Fn>
void forEachLine(std::string_view text, Fn&& fn) {
  size_t pos = 0;
  int lineNo = 0;
  while (pos < text.size()) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    size_t nul = line.find('\0');
    if (nul != std::string_view::npos) line = line.substr(0, nul);
    ++lineNo;
    fn(lineNo, line);
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n')
      ++end;
    pos = end + 1;
  }
}

bool isBlank(char c) { return c == ' ' || c == '\t'; }

std::string_view trimLeft(std::string_view s) {
  size_t i = 0;
  while (i < s.size() && isBlank(s[i])) ++i;
  return s.substr(i);
}

std::string_view trimRight(std::string_view s) {
  size_t n = s.size();
  while (n > 0 && (isBlank(s[n - 1]) || s[n - 1] == '\r' || s[n - 1] == '\n')) --n;
  return s.substr(0, n);
}

// `line` (left-trimmed) starts with keyword `kw` followed by a blank (tinyobj's test).
bool startsWithKeyword(std::string_view line, std::string_view kw) {
  return line.size() > kw.size() && line.substr(0, kw.size()) == kw && isBlank(line[kw.size()]);
}

// Splits off the next blank-separated token.
std::string_view nextToken(std::string_view& s) {
  s = trimLeft(s);
  size_t n = 0;
  while (n < s.size() && !isBlank(s[n])) ++n;
  std::string_view tok = s.substr(0, n);
  s = s.substr(n);
  return tok;
}

// The value a real-number token stands for, as the float tinyobj would store; nullopt
// when it is not a number at all (tinyobj then uses 0, which is not our concern here).
std::optional<float> tokenAsFloat(std::string_view tok) {
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
  double d = 0;
  auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), d);
  if (ec == std::errc::result_out_of_range) {
    // Over- or underflow: strtod tells which (HUGE_VAL or a tiny value).
    std::string copy(tok);
    d = std::strtod(copy.c_str(), nullptr);
  } else if (ec != std::errc() || ptr == tok.data()) {
    return std::nullopt;
  }
  return static_cast<float>(d);
}

// atoi-like parse of an OBJ index (the part of `s` up to '/', blank or end); saturates
// instead of overflowing. Advances `s` past the digits and anything up to '/' or a blank.
long long parseIndex(std::string_view& s) {
  size_t i = 0;
  bool neg = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
  long long v = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    v = std::min<long long>(v * 10 + (s[i] - '0'), 1LL << 40);
    ++i;
  }
  while (i < s.size() && s[i] != '/' && !isBlank(s[i])) ++i;
  s = s.substr(i);
  return neg ? -v : v;
}

std::string fmtFloat(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

std::string fmtVec(const Vec3& v) {
  return "(" + fmtFloat(v.x) + ", " + fmtFloat(v.y) + ", " + fmtFloat(v.z) + ")";
}

// ---------------------------------------------------------------------------------------
// OBJ pre-scan: counts, index ranges and finite coordinates, with line numbers.

struct ObjScan {
  uint64_t positions = 0, texcoords = 0, normals = 0;
  uint64_t triangles = 0;  // upper bound of what tinyobj's triangulation produces
  std::vector<std::string> mtllibArgs;  // raw text after each `mtllib`
};

// The most corners one face may have (tinyobj triangulates a polygon in quadratic time).
constexpr int kMaxFaceVertices = 4096;

// Index kinds, for messages.
const char* const kIndexWhat[3] = {"vertex", "texture coordinate", "normal"};
const char* const kIndexLine[3] = {"v", "vt", "vn"};

// A limit error: at the obj_mesh that named the file when there is one (the place to look
// in the .ray file), else without a location.
[[noreturn]] void throwLimit(const SourceLoc& referredFrom, const std::string& msg) {
  if (referredFrom.line > 0) throw Error(referredFrom, msg);
  throw Error(msg);
}

ObjScan scanObj(const std::string& text, const std::string& path, const Limits& limits,
                const SourceLoc& referredFrom) {
  ObjScan scan;
  // Largest positive index seen per kind and its line: positive indices may refer
  // forward (tinyobj allows it), so they are checked against the final counts.
  long long maxIndex[3] = {0, 0, 0};
  int maxIndexLine[3] = {0, 0, 0};

  auto checkFinite = [&](std::string_view rest, int count, int lineNo, const char* what) {
    for (int i = 0; i < count; ++i) {
      std::string_view tok = nextToken(rest);
      if (tok.empty()) return;
      std::optional<float> v = tokenAsFloat(tok);
      if (v && !std::isfinite(*v))
        throw Error(SourceLoc{path, lineNo, 0},
                    std::string(what) + " coordinate '" + std::string(tok) +
                        "' is not a finite number");
    }
  };

  forEachLine(text, [&](int lineNo, std::string_view raw) {
    std::string_view line = trimLeft(raw);
    if (line.empty() || line[0] == '#') return;
    if (startsWithKeyword(line, "v")) {
      ++scan.positions;
      checkFinite(line.substr(2), 3, lineNo, "vertex");
    } else if (startsWithKeyword(line, "vt")) {
      ++scan.texcoords;
      checkFinite(line.substr(3), 2, lineNo, "texture");
    } else if (startsWithKeyword(line, "vn")) {
      ++scan.normals;
      checkFinite(line.substr(3), 3, lineNo, "normal");
    } else if (startsWithKeyword(line, "mtllib")) {
      scan.mtllibArgs.emplace_back(trimRight(trimLeft(line.substr(7))));
    } else if (startsWithKeyword(line, "f")) {
      // Mirrors tinyobj's parseTriple: i, i/j, i//k, i/j/k.
      std::string_view rest = trimRight(line.substr(2));
      uint64_t counts[3] = {scan.positions, scan.texcoords, scan.normals};
      int corners = 0;
      while (true) {
        rest = trimLeft(rest);
        if (rest.empty()) break;
        long long idx[3] = {0, 0, 0};
        bool present[3] = {true, false, false};
        idx[0] = parseIndex(rest);
        if (!rest.empty() && rest[0] == '/') {
          rest.remove_prefix(1);
          if (!rest.empty() && rest[0] == '/') {
            rest.remove_prefix(1);
            idx[2] = parseIndex(rest);
            present[2] = true;
          } else {
            idx[1] = parseIndex(rest);
            present[1] = true;
            if (!rest.empty() && rest[0] == '/') {
              rest.remove_prefix(1);
              idx[2] = parseIndex(rest);
              present[2] = true;
            }
          }
        }
        for (int k = 0; k < 3; ++k) {
          if (!present[k]) continue;
          if (idx[k] == 0)
            throw Error(SourceLoc{path, lineNo, 0},
                        std::string("face has ") + kIndexWhat[k] +
                            " index 0 (or a non-number); OBJ indices start at 1");
          if (idx[k] < 0 && uint64_t(-idx[k]) > counts[k])
            throw Error(SourceLoc{path, lineNo, 0},
                        std::string(kIndexWhat[k]) + " index " + std::to_string(idx[k]) +
                            " is out of range: only " + std::to_string(counts[k]) + " '" +
                            kIndexLine[k] + "' lines precede it");
          if (idx[k] > maxIndex[k]) {
            maxIndex[k] = idx[k];
            maxIndexLine[k] = lineNo;
          }
        }
        ++corners;
        // tinyobj skips blanks and '\r' between corners; anything after the third
        // component up to the next blank was consumed by parseIndex.
      }
      // tinyobj's ear clipping takes time growing with the square of a polygon's size (a
      // face of 200,000 corners ran for minutes): larger faces are refused here.
      if (corners > kMaxFaceVertices)
        throw Error(SourceLoc{path, lineNo, 0},
                    "face has " + std::to_string(corners) + " vertices, more than " +
                        std::to_string(kMaxFaceVertices) + " in one polygon (split it into smaller faces)");
      if (corners >= 3) scan.triangles += uint64_t(corners - 2);
    }
  });

  uint64_t finalCounts[3] = {scan.positions, scan.texcoords, scan.normals};
  for (int k = 0; k < 3; ++k)
    if (maxIndex[k] > 0 && uint64_t(maxIndex[k]) > finalCounts[k])
      throw Error(SourceLoc{path, maxIndexLine[k], 0},
                  std::string(kIndexWhat[k]) + " index " + std::to_string(maxIndex[k]) +
                      " is out of range: the file has " + std::to_string(finalCounts[k]) +
                      " '" + kIndexLine[k] + "' lines");

  if (scan.triangles > limits.maxTriangles)
    throwLimit(referredFrom, "OBJ file " + quoteInput(path) + " has " + std::to_string(scan.triangles) +
                " triangles, more than the limit of " + std::to_string(limits.maxTriangles) +
                " (raise it with --max-triangles)");
  if (scan.positions > limits.maxVertices)
    throwLimit(referredFrom, "OBJ file " + quoteInput(path) + " has " + std::to_string(scan.positions) +
                " vertices, more than the limit of " + std::to_string(limits.maxVertices) +
                " (raise it with --max-triangles)");
  // Checked here, before the mesh is built; the parser counts it once it is complete.
  const uint64_t bytes = scan.positions * memory_cost::kMeshVertex + scan.triangles * memory_cost::kMeshTriangle;
  if (!processBudget().fits(bytes))
    throwLimit(referredFrom, processBudget().overBudget(
                                 bytes, "the " + std::to_string(scan.triangles) + " triangles of OBJ file " + quoteInput(path)));
  return scan;
}

// ---------------------------------------------------------------------------------------
// MTL scan: which keywords each material block lists, and where.

enum MtlKey : unsigned {
  kKa = 1u << 0, kKd = 1u << 1, kKs = 1u << 2, kKe = 1u << 3, kNs = 1u << 4,
  kNi = 1u << 5, kD = 1u << 6, kTr = 1u << 7, kMapKd = 1u << 8, kMapKe = 1u << 9,
};

struct MtlRecord {
  std::string name;
  int line = 0;       // of `newmtl`
  unsigned keys = 0;  // MtlKey bits
  int mapKdLine = 0, mapKeLine = 0;
};

// One record per material tinyobj's LoadMtl pushes, in the same order (it flushes the
// current material at each named `newmtl` and always once at the end).
std::vector<MtlRecord> scanMtl(const std::string& text) {
  std::vector<MtlRecord> out;
  MtlRecord cur;
  static const std::pair<const char*, unsigned> kKeys[] = {
      {"Ka", kKa}, {"Kd", kKd}, {"Ks", kKs}, {"Ke", kKe}, {"Ns", kNs},
      {"Ni", kNi}, {"d", kD},   {"Tr", kTr}, {"map_Kd", kMapKd}, {"map_Ke", kMapKe}};
  forEachLine(text, [&](int lineNo, std::string_view raw) {
    std::string_view line = trimLeft(trimRight(raw));
    if (line.empty() || line[0] == '#') return;
    if (startsWithKeyword(line, "newmtl")) {
      if (!cur.name.empty()) out.push_back(cur);
      cur = MtlRecord{};
      cur.name = std::string(line.substr(7));
      cur.line = lineNo;
      return;
    }
    for (const auto& [kw, bit] : kKeys) {
      if (startsWithKeyword(line, kw)) {
        cur.keys |= bit;
        if (bit == kMapKd) cur.mapKdLine = lineNo;
        if (bit == kMapKe) cur.mapKeLine = lineNo;
        return;
      }
    }
  });
  out.push_back(cur);
  return out;
}

struct MtlFile {
  std::string path;
  size_t first = 0, last = 0;        // the range of tinyobj material ids it produced
  std::vector<MtlRecord> records;    // aligned with that range when sizes agree
};

// tinyobj's SplitString removes '\' escapes from mtllib names; undo that for the names
// that used '\' as a Windows separator so that we can still find their base name.
std::string unescapeMtllib(const std::string& s) {
  std::string r;
  bool esc = false;
  for (char c : s) {
    if (!esc && c == '\\') {
      esc = true;
      continue;
    }
    esc = false;
    r += c;
  }
  return r;
}

bool isRegularFile(const std::string& p) {
  std::error_code ec;
  return !p.empty() && fs::is_regular_file(p, ec);
}

// Finds each `mtllib` file at its path relative to the .obj, else by its base name beside
// the .obj. A library that is found nowhere is a warning; its faces get the default
// material (tinyobj reports usemtl of unknown names as warnings too).
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(std::string objPath, const std::vector<std::string>& mtllibArgs, const Limits& limits)
      : objPath_(std::move(objPath)), objDir_(parentDir(objPath_)), limits_(limits) {
    for (const std::string& raw : mtllibArgs) {
      // Only single-name lines can be matched back to their raw text reliably.
      if (raw.find('\\') != std::string::npos) rawWithBackslash_.push_back(raw);
    }
  }

  bool operator()(const std::string& matId, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* matMap, std::string* warn,
                  std::string* err) override {
    std::vector<std::string> candidates;
    auto add = [&](const std::string& rel) {
      std::string p = fs::path(resolveRelative(objDir_, rel)).lexically_normal().string();
      if (std::find(candidates.begin(), candidates.end(), p) == candidates.end())
        candidates.push_back(p);
    };
    add(matId);
    add(fs::path(matId).filename().string());
    for (const std::string& raw : rawWithBackslash_) {
      if (unescapeMtllib(raw) != matId) continue;
      std::string slashed = raw;
      std::replace(slashed.begin(), slashed.end(), '\\', '/');
      add(slashed);
      add(fs::path(slashed).filename().string());
    }
    std::string directory;  // a candidate that exists but is a directory
    for (const std::string& p : candidates) {
      if (!isRegularFile(p)) {
        std::error_code dec;
        if (directory.empty() && fs::is_directory(p, dec)) directory = p;
        continue;
      }
      std::error_code ec;
      uintmax_t size = fs::file_size(p, ec);
      if (!ec && size > limits_.maxFileBytes) {
        if (err) *err += "material library " + quoteInput(p) + " is larger than " +
                         std::to_string(limits_.maxFileBytes) + " bytes\n";
        return false;
      }
      std::string text = readFile(p);
      std::istringstream in(text);
      MtlFile file;
      file.path = p;
      file.first = materials->size();
      std::string w;
      tinyobj::LoadMtl(matMap, materials, &in, &w, err);
      file.last = materials->size();
      file.records = scanMtl(text);
      if (file.records.size() != file.last - file.first) file.records.clear();
      files.push_back(std::move(file));
      // tinyobj's MTL warnings are about d/Tr precedence, which we document instead.
      return true;
    }
    if (!directory.empty()) {
      missing.push_back(objPath_ + ": warning: material library " + quoteInput(matId) +
                        " is a directory (" + quoteInput(directory) +
                        "), not a file; using default materials");
      (void)warn;
      return false;
    }
    std::string msg = objPath_ + ": warning: material library " + quoteInput(matId) + " not found (looked for";
    for (size_t i = 0; i < candidates.size(); ++i) msg += (i ? ", '" : " '") + candidates[i] + "'";
    msg += "); using default materials";
    missing.push_back(msg);
    (void)warn;
    return false;
  }

  std::vector<MtlFile> files;
  std::vector<std::string> missing;

 private:
  std::string objPath_, objDir_;
  const Limits& limits_;
  std::vector<std::string> rawWithBackslash_;
};

// ---------------------------------------------------------------------------------------
// Materials

Color toColor(const tinyobj::real_t c[3]) { return Color(float(c[0]), float(c[1]), float(c[2])); }

std::optional<TextureRef> textureRef(const std::string& name, const std::string& mtlPath, int line,
                                     std::vector<std::string>& warnings) {
  std::string n(trimRight(trimLeft(name)));
  if (n.empty()) return std::nullopt;
  std::replace(n.begin(), n.end(), '\\', '/');
  std::string dir = parentDir(mtlPath);
  std::string p = fs::path(resolveRelative(dir, n)).lexically_normal().string();
  if (!isRegularFile(p)) {
    std::string alt =
        fs::path(resolveRelative(dir, fs::path(n).filename().string())).lexically_normal().string();
    if (!isRegularFile(alt)) {
      warnings.push_back(SourceLoc{mtlPath, line, 0}.str() + ": warning: texture '" + name +
                         "' not found (looked for " + quoteInput(p) + "" + (alt != p ? " and " + quoteInput(alt) + "" : "") +
                         "); using the constant colour");
      return std::nullopt;
    }
    p = alt;
  }
  TextureRef ref;
  ref.path = p;
  ref.loc = SourceLoc{mtlPath, line, 0};
  ref.srgb = true;
  return ref;
}

// Converts one tinyobj material. `rec` may be null (scan did not line up): then every
// keyword counts as present.
// `*luminous` tells whether the MTL made a luminosity (one inherited from `base` keeps
// its own intensity and density).
MaterialDesc convertMaterial(const tinyobj::material_t& m, const MtlRecord* rec,
                             const std::string& mtlPath, const MaterialDesc& base,
                             std::vector<std::string>& warnings, bool* luminous) {
  *luminous = false;
  unsigned keys = rec ? rec->keys : ~0u;
  MaterialDesc d = base;
  d.name = m.name;
  d.loc = SourceLoc{mtlPath, rec ? rec->line : 0, 0};
  if (keys & kKd) d.diffuse = ColorParam{toColor(m.diffuse), std::nullopt};
  if (keys & kKs) d.specular = ColorParam{toColor(m.specular), std::nullopt};
  if (keys & kKa) d.ambient = ColorParam{toColor(m.ambient), std::nullopt};
  if (keys & kNs) d.shininess = ScalarParam{float(m.shininess), std::nullopt};
  if (keys & kNi) d.index = ScalarParam{float(m.ior), std::nullopt};
  if (keys & (kD | kTr)) {
    float t = std::clamp(1.0f - float(m.dissolve), 0.0f, 1.0f);
    d.transmissive = ColorParam{Color(t, t, t), std::nullopt};
  }
  if (!m.diffuse_texname.empty()) {
    if (auto ref = textureRef(m.diffuse_texname, mtlPath, rec ? rec->mapKdLine : 0, warnings))
      d.diffuse.map = ref;
  }
  std::optional<TextureRef> keMap;
  if (!m.emissive_texname.empty())
    keMap = textureRef(m.emissive_texname, mtlPath, rec ? rec->mapKeLine : 0, warnings);

  Color ke = (keys & kKe) ? vmax(toColor(m.emission), Color(0, 0, 0)) : Color(0, 0, 0);
  if (keys & kKe) {
    d.emissive = ColorParam{toColor(m.emission), std::nullopt};
    d.emissiveSet = true;
    d.luminosity.reset();
  }
  float keMax = maxComponent(ke);
  if (keMax > 0 || keMap) {
    LuminosityDesc l;
    l.colour = ColorParam{keMax > 0 ? ke / keMax : Color(1, 1, 1), keMap};
    // intensity and density need the material's area: filled in by loadObj.
    l.intensity = keMax > 0 ? keMax : 1.0f;
    l.density = 1;
    l.loc = d.loc;
    d.luminosity = l;
    *luminous = true;
  }
  return d;
}

// ---------------------------------------------------------------------------------------
// Mesh building

struct CornerKey {
  int v, vt, vn;
  bool operator==(const CornerKey& o) const { return v == o.v && vt == o.vt && vn == o.vn; }
};

struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t(uint32_t(k.vt)) + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
    h ^= (uint64_t(uint32_t(k.vn)) + 0x165667B19E3779F9ull) * 0x27D4EB2F165667C5ull;
    h ^= h >> 29;
    return size_t(h);
  }
};

// The line number in a tinyobj message ("... line 12.)" or "line: 12"), or 0.
int lineFromTinyobj(const std::string& msg) {
  static const std::regex re(R"(line:? ?(\d+))");
  std::smatch m;
  if (std::regex_search(msg, m, re)) return std::atoi(m[1].str().c_str());
  return 0;
}

void openCheck(const std::string& path, const SourceLoc& referredFrom, const Limits& limits) {
  auto fail = [&](const std::string& why) {
    std::string msg = "cannot open OBJ file " + quoteInput(path) + ": " + why;
    if (referredFrom.line > 0) throw Error(referredFrom, msg);
    throw Error(msg);
  };
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail(std::strerror(EISDIR));
  // A device or FIFO could block or never end (obj_mesh { file = "/dev/zero"; }).
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec)) fail("not a regular file");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) fail(std::strerror(errno));
  std::fclose(f);
  uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > limits.maxFileBytes)
    fail("the file is larger than " + std::to_string(limits.maxFileBytes) + " bytes");
}

}  // namespace

// -----------------------------------------------------------------------------------------

namespace {

// The text as a stream for tinyobj, without a copy (an istringstream copied it: 73 MB for
// 2M triangles), handed out a block at a time so that `progress` hears how far the parse is.
class ProgressStreambuf : public std::streambuf {
 public:
  ProgressStreambuf(const std::string& text, Progress& progress) : text_(text), progress_(progress) {}

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    const size_t at = egptr() ? size_t(egptr() - text_.data()) : 0;
    if (at >= text_.size()) return traits_type::eof();
    const size_t n = std::min(kBlock, text_.size() - at);
    char* b = const_cast<char*>(text_.data()) + at;  // read only: the get area is never written
    setg(b, b, b + n);
    progress_.add(2.0 * double(n));
    return traits_type::to_int_type(*gptr());
  }

 private:
  static constexpr size_t kBlock = size_t(1) << 20;
  const std::string& text_;
  Progress& progress_;
};

}  // namespace

ObjData loadObj(const std::string& path, const SourceLoc& referredFrom, const MaterialDesc& base,
                const Limits& limits, const ProgressFn& progressFn) {
  openCheck(path, referredFrom, limits);
  std::string text = readFile(path);
  // Shares of the progress: the scan a quarter, tinyobj's reading of the text half (it
  // builds its shapes after; 0.8 s of a 2M-triangle file's 2.6 s), the meshes built from
  // them the last quarter.
  Progress progress(progressFn, 4.0 * double(text.size()));
  progress.add(0);  // the bar's clock starts here
  ObjScan scan = scanObj(text, path, limits, referredFrom);
  progress.add(double(text.size()));

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> tmats;
  std::string warn, err;
  MtlReader reader(path, scan.mtllibArgs, limits);
  ProgressStreambuf buf(text, progress);
  std::istream in(&buf);
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &tmats, &warn, &err, &in, &reader,
                             /*triangulate=*/true, /*default_vcols_fallback=*/false);
  if (!ok || !err.empty()) {
    std::string msg = std::string(trimRight(err.empty() ? "tinyobjloader failed" : err));
    int line = lineFromTinyobj(msg);
    throw Error(SourceLoc{path, line, 0}, "cannot parse OBJ file: " + msg);
  }

  ObjData out;
  out.warnings = reader.missing;
  {
    std::istringstream ws(warn);
    std::string w;
    while (std::getline(ws, w)) {
      w = std::string(trimRight(trimLeft(w)));
      if (w.empty() || w == "." || w.rfind("Failed to load material file", 0) == 0) continue;
      int line = lineFromTinyobj(w);
      out.warnings.push_back(SourceLoc{path, line, 0}.str() + ": warning: " + w);
    }
  }

  // Belt and braces: the scan has checked the text; these are what tinyobj stored.
  for (tinyobj::real_t x : attrib.vertices)
    if (!std::isfinite(x)) throw Error(SourceLoc{path, 0, 0}, "a vertex coordinate is not finite");
  for (tinyobj::real_t x : attrib.normals)
    if (!std::isfinite(x)) throw Error(SourceLoc{path, 0, 0}, "a normal is not finite");
  for (tinyobj::real_t x : attrib.texcoords)
    if (!std::isfinite(x)) throw Error(SourceLoc{path, 0, 0}, "a texture coordinate is not finite");

  const int nv = int(attrib.vertices.size() / 3);
  const int nvt = int(attrib.texcoords.size() / 2);
  const int nvn = int(attrib.normals.size() / 3);

  // Which attributes every used corner has, and which materials faces use.
  uint64_t triCount = 0;
  bool allVt = true, allVn = true;
  std::vector<char> used(tmats.size() + 1, 0);  // [0] = no material (-1)
  for (const tinyobj::shape_t& s : shapes) {
    const auto& mesh = s.mesh;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      if (mesh.num_face_vertices[f] != 3)
        throw Error(SourceLoc{path, 0, 0}, "internal: tinyobj returned a non-triangle face");
      int mid = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      if (mid < -1 || mid >= int(tmats.size())) mid = -1;
      used[size_t(mid + 1)] = 1;
    }
    for (const tinyobj::index_t& ix : mesh.indices) {
      if (ix.vertex_index < 0 || ix.vertex_index >= nv ||
          ix.texcoord_index >= nvt || ix.normal_index >= nvn)
        throw Error(SourceLoc{path, 0, 0}, "a face index is out of range");
      allVt = allVt && ix.texcoord_index >= 0;
      allVn = allVn && ix.normal_index >= 0;
    }
    triCount += mesh.num_face_vertices.size();
  }
  if (triCount > limits.maxTriangles)
    throwLimit(referredFrom, "OBJ file " + quoteInput(path) + " has " + std::to_string(triCount) +
                " triangles, more than the limit of " + std::to_string(limits.maxTriangles) +
                " (raise it with --max-triangles)");

  // Materials: the MTL materials faces use, in MTL order, then the default when some
  // faces have none (or when no face uses any, so that the list is never empty).
  std::vector<int> matIndex(tmats.size() + 1, -1);
  std::vector<char> mtlLuminous;  // per out.materials entry
  for (const MtlFile& file : reader.files) {
    for (size_t i = file.first; i < file.last; ++i) {
      if (!used[i + 1]) continue;
      const MtlRecord* rec = file.records.empty() ? nullptr : &file.records[i - file.first];
      if (rec && rec->name != tmats[i].name) rec = nullptr;
      matIndex[i + 1] = int(out.materials.size());
      bool lum = false;
      out.materials.push_back(convertMaterial(tmats[i], rec, file.path, base, out.warnings, &lum));
      mtlLuminous.push_back(lum);
    }
  }
  if (used[0] || out.materials.empty()) {
    MaterialDesc def = base;
    def.name.clear();
    def.diffuse = ColorParam{Color(0.8f, 0.8f, 0.8f), std::nullopt};
    def.loc = SourceLoc{path, 0, 0};
    matIndex[0] = int(out.materials.size());
    out.materials.push_back(def);
    mtlLuminous.push_back(0);
  }

  // Vertices: one per distinct (v, vt, vn) actually used, in first-use order.
  MeshDesc& mesh = out.mesh;
  mesh.triangles.reserve(size_t(triCount));
  mesh.triangleMaterials.reserve(size_t(triCount));
  std::unordered_map<CornerKey, int, CornerHash> vertexOf;
  vertexOf.reserve(size_t(std::min<uint64_t>(triCount * 3, uint64_t(nv) * 4 + 16)));
  for (const tinyobj::shape_t& s : shapes) {
    const auto& sm = s.mesh;
    for (size_t f = 0; f < sm.num_face_vertices.size(); ++f) {
      std::array<int, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        const tinyobj::index_t& ix = sm.indices[3 * f + size_t(c)];
        CornerKey key{ix.vertex_index, allVt ? ix.texcoord_index : -1, allVn ? ix.normal_index : -1};
        auto [it, inserted] = vertexOf.try_emplace(key, int(mesh.points.size()));
        if (inserted) {
          if (mesh.points.size() >= limits.maxVertices)
            throwLimit(referredFrom, "OBJ file " + quoteInput(path) + " has more than " +
                        std::to_string(limits.maxVertices) +
                        " distinct vertices (raise it with --max-triangles)");
          const size_t v = size_t(key.v);
          Vec3 p(float(attrib.vertices[3 * v]), float(attrib.vertices[3 * v + 1]),
                 float(attrib.vertices[3 * v + 2]));
          mesh.points.push_back(p);
          out.bounds.extend(p);
          if (allVn) {
            const size_t n = size_t(key.vn);
            mesh.normals.emplace_back(float(attrib.normals[3 * n]), float(attrib.normals[3 * n + 1]),
                                      float(attrib.normals[3 * n + 2]));
          }
          if (allVt) {
            const size_t t = size_t(key.vt);
            mesh.uvs.emplace_back(float(attrib.texcoords[2 * t]), float(attrib.texcoords[2 * t + 1]));
          }
        }
        tri[size_t(c)] = it->second;
      }
      int mid = f < sm.material_ids.size() ? sm.material_ids[f] : -1;
      if (mid < -1 || mid >= int(tmats.size())) mid = -1;
      mesh.triangles.push_back(tri);
      mesh.triangleMaterials.push_back(matIndex[size_t(mid + 1)]);
    }
  }
  mesh.genNormals = false;

  // Luminous materials: intensity and density from their faces' area (see the top).
  std::vector<double> area(out.materials.size(), 0.0);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    Vec3 a = mesh.points[size_t(tri[0])], b = mesh.points[size_t(tri[1])], c = mesh.points[size_t(tri[2])];
    double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
    double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
           cz = e1[0] * e2[1] - e1[1] * e2[0];
    area[size_t(mesh.triangleMaterials[t])] += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  }
  for (size_t i = 0; i < out.materials.size(); ++i) {
    MaterialDesc& m = out.materials[i];
    if (!mtlLuminous[i]) continue;
    double a = area[i];
    if (!(a > 0) || !std::isfinite(a)) {
      out.warnings.push_back(m.loc.str() + ": warning: luminous material '" + m.name +
                             "' is used only by faces of zero area; it emits no light");
      m.luminosity.reset();
      continue;
    }
    m.luminosity->intensity = float(double(m.luminosity->intensity) * a);
    m.luminosity->density = float(1000.0 / a);
  }
  return out;
}

namespace {

// Default camera: vertical fov 45 degrees, looking along -z from +z at the centre of the
// bounds, far enough that the bounding sphere fits vertically. It looks from -z instead
// when the +z side of the bounds is "closed" and the -z side open, i.e. when more face
// area lies in the bounds' max-z plane than in its min-z plane (a Cornell box modelled
// with its opening towards -z, like the original Cornell data).
CameraDesc defaultCamera(const MeshDesc& mesh, const Bounds3& boundsIn, const std::string& path) {
  Bounds3 bounds = boundsIn;
  if (bounds.empty()) bounds = Bounds3(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  Vec3 c = bounds.center();
  float r = 0.5f * bounds.diagonal();
  if (!(r > 0)) r = 1;
  double areaLo = 0, areaHi = 0;
  float eps = 1e-5f * std::max(1.0f, 2 * r);
  for (const auto& tri : mesh.triangles) {
    const Vec3& a = mesh.points[size_t(tri[0])];
    const Vec3& b = mesh.points[size_t(tri[1])];
    const Vec3& d = mesh.points[size_t(tri[2])];
    double area = 0.5 * double(length(cross(b - a, d - a)));
    auto onPlane = [&](float z) {
      return std::fabs(a.z - z) <= eps && std::fabs(b.z - z) <= eps && std::fabs(d.z - z) <= eps;
    };
    if (onPlane(bounds.lo.z)) areaLo += area;
    if (onPlane(bounds.hi.z)) areaHi += area;
  }
  float back = areaHi > areaLo ? -1.0f : 1.0f;  // which side the camera is on
  const float fov = 45.0f;
  float dist = r / std::sin(0.5f * fov * kPi / 180.0f);
  CameraDesc cam;
  cam.position = c + Vec3(0, 0, back * dist);
  cam.viewDir = Vec3(0, 0, -back);
  cam.upDir = Vec3(0, 1, 0);
  cam.fovDegrees = fov;
  cam.loc = SourceLoc{path, 0, 0};
  return cam;
}

// Default light rig, used only when no face has a luminous (Ke) material. Constant
// attenuation (1, 0, 0) so brightness does not depend on the model's units:
//   key:  colour 0.8 at the camera, raised and moved right by half the bounding radius
//         (so shadows fall down-left of objects and stay visible);
//   fill: colour 0.3 at the bounds' distance from the centre, up-left in front.
std::vector<LightDesc> defaultLights(const CameraDesc& cam, const Bounds3& boundsIn,
                                     const std::string& path) {
  Bounds3 bounds = boundsIn;
  if (bounds.empty()) bounds = Bounds3(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  Vec3 c = bounds.center();
  float r = 0.5f * bounds.diagonal();
  if (!(r > 0)) r = 1;
  Vec3 up = cam.upDir;
  Vec3 right = normalize(cross(cam.viewDir, up));
  Vec3 back = -cam.viewDir;
  float dist = lengthScaled(cam.position - c);  // (a model near 1e30 overflows length())
  LightDesc key;
  key.position = cam.position + (up + right) * (0.5f * r);
  key.colour = Color(0.8f, 0.8f, 0.8f);
  LightDesc fill;
  fill.position = c + normalize(up - right + back) * dist;
  fill.colour = Color(0.3f, 0.3f, 0.3f);
  std::vector<LightDesc> lights{key, fill};
  for (LightDesc& l : lights) {
    l.kind = LightKind::Point;
    l.attenConstant = 1;
    l.attenLinear = 0;
    l.attenQuadratic = 0;
    l.loc = SourceLoc{path, 0, 0};
  }
  return lights;
}

// When the default camera or lights overflow a float (vertices near +-1e38): an error at
// the `v` line with the largest coordinate, the vertex that put them out of range.
void checkDefaultsFinite(const SceneDesc& s, const std::string& path) {
  bool finite = isFinite(s.camera.position);
  for (const LightDesc& l : s.lights) finite = finite && isFinite(l.position);
  if (finite) return;
  std::string text = readFile(path);
  float largest = -1;
  int largestLine = 0;
  std::string coords;
  forEachLine(text, [&](int lineNo, std::string_view raw) {
    std::string_view line = trimLeft(raw);
    if (!startsWithKeyword(line, "v")) return;
    std::string_view rest = line.substr(2);
    std::string here;
    float m = 0;
    for (int i = 0; i < 3; ++i) {
      std::string_view tok = nextToken(rest);
      if (tok.empty()) break;
      here += (i ? ", " : "") + std::string(tok);
      if (std::optional<float> v = tokenAsFloat(tok)) m = std::max(m, std::fabs(*v));
    }
    if (m > largest) largest = m, largestLine = lineNo, coords = here;
  });
  std::string msg = "the default camera and lights for this model are out of range for a float";
  if (largestLine > 0)
    throw Error(SourceLoc{path, largestLine, 0},
                "vertex (" + coords + ") is too far from the origin: " + msg +
                    " (scale the model down)");
  throw Error(SourceLoc{path, 0, 0}, msg);
}

std::string describe(const SceneDesc& s, int luminousMaterials) {
  std::string d = "// default camera framing the model\ncamera {\n";
  d += "  position = " + fmtVec(s.camera.position) + ";\n";
  d += "  viewdir = " + fmtVec(s.camera.viewDir) + ";\n";
  d += "  updir = " + fmtVec(s.camera.upDir) + ";\n";
  d += "  fov = " + fmtFloat(s.camera.fovDegrees) + ";\n}\n";
  if (luminousMaterials > 0) {
    d += "// lit by " + std::to_string(luminousMaterials) +
         " luminous (Ke) material(s) of the MTL: no default lights\n";
  } else {
    d += "// default lights (the MTL has no luminous Ke material)\n";
    for (const LightDesc& l : s.lights) {
      d += "point_light {\n  position = " + fmtVec(l.position) + ";\n";
      d += "  colour = " + fmtVec(l.colour) + ";\n";
      d += "  constant_attenuation_coeff = " + fmtFloat(l.attenConstant) + ";\n";
      d += "  linear_attenuation_coeff = " + fmtFloat(l.attenLinear) + ";\n";
      d += "  quadratic_attenuation_coeff = " + fmtFloat(l.attenQuadratic) + ";\n}\n";
    }
  }
  return d;
}

}  // namespace

SceneDesc loadObjScene(const std::string& path, const Limits& limits, std::string* description,
                       const ProgressFn& progress) {
  // MTL materials start from the .ray format's initial default material.
  const MaterialDesc initial{};
  ObjData obj = loadObj(path, SourceLoc{}, initial, limits, progress);

  SceneDesc s;
  s.path = path;
  s.warnings = obj.warnings;
  s.materials.push_back(initial);  // index 0: the initial default material
  int luminous = 0;
  for (MaterialDesc& m : obj.materials) {
    if (m.luminosity) ++luminous;
    s.materials.push_back(std::move(m));
  }
  // triangleMaterials index SceneDesc::materials: shift past the initial default.
  for (int& m : obj.mesh.triangleMaterials) m += 1;
  ObjectDesc o;
  o.kind = ShapeKind::Mesh;
  o.transform = Mat4::identity();
  o.material = obj.mesh.triangleMaterials.empty() ? 1 : obj.mesh.triangleMaterials[0];
  o.mesh = 0;
  o.name = fs::path(path).stem().string();
  o.loc = SourceLoc{path, 0, 0};
  s.meshes.push_back(std::move(obj.mesh));
  s.objects.push_back(std::move(o));

  s.camera = defaultCamera(s.meshes[0], obj.bounds, path);
  s.hasCamera = true;
  if (luminous == 0) s.lights = defaultLights(s.camera, obj.bounds, path);
  checkDefaultsFinite(s, path);
  if (description) *description = describe(s, luminous);
  return s;
}

void writeRayFromObj(const std::string& objPath, const std::string& outPath, const Limits& limits) {
  checkWritable(outPath);
  SceneDesc s = loadObjScene(objPath, limits, nullptr);

  // One polymesh per material: each keeps the vertices its triangles use, in first-use
  // order, with their exact float data, and the triangles keep their corner order, so
  // the .ray renders the same image as the .obj.
  const MeshDesc& all = s.meshes.at(0);
  std::vector<MeshDesc> meshes;
  std::vector<ObjectDesc> objects;
  for (int mi = 0; mi < int(s.materials.size()); ++mi) {
    MeshDesc part;
    part.genNormals = all.genNormals;
    std::unordered_map<int, int> remap;
    for (size_t t = 0; t < all.triangles.size(); ++t) {
      if (all.triangleMaterials[t] != mi) continue;
      std::array<int, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        int v = all.triangles[t][size_t(c)];
        auto [it, inserted] = remap.try_emplace(v, int(part.points.size()));
        if (inserted) {
          part.points.push_back(all.points[size_t(v)]);
          if (!all.normals.empty()) part.normals.push_back(all.normals[size_t(v)]);
          if (!all.uvs.empty()) part.uvs.push_back(all.uvs[size_t(v)]);
        }
        tri[size_t(c)] = it->second;
      }
      part.triangles.push_back(tri);
    }
    if (part.triangles.empty()) continue;
    ObjectDesc o = s.objects.at(0);
    o.material = mi;
    o.mesh = int(meshes.size());
    o.name = s.materials[size_t(mi)].name;
    meshes.push_back(std::move(part));
    objects.push_back(std::move(o));
  }
  s.meshes = std::move(meshes);
  s.objects = std::move(objects);

  // Texture paths absolute, so the writer can make them relative to the output's folder.
  auto absolutize = [](std::optional<TextureRef>& ref) {
    if (ref) ref->path = fs::absolute(ref->path).lexically_normal().string();
  };
  for (MaterialDesc& m : s.materials) {
    for (ColorParam* c : {&m.emissive, &m.ambient, &m.diffuse, &m.specular, &m.reflective,
                          &m.transmissive})
      absolutize(c->map);
    absolutize(m.shininess.map);
    absolutize(m.index.map);
    if (m.luminosity) absolutize(m.luminosity->colour.map);
  }

  RayWriteOptions opts;
  opts.bakeTransforms = true;
  std::string outDir = parentDir(outPath);
  opts.relativeTo = fs::absolute(outDir.empty() ? "." : outDir).lexically_normal().string();
  writeRayFile(outPath, s, opts);
}

}  // namespace lc::io
