// .ray writer. The output reads back (parseRayString) to the same camera, lights,
// per-object materials, meshes and transforms: floats and matrix entries (doubles) are
// printed in the shortest form that reads back to the same value (0.63, not 0.629999995).
//
// It never writes a top-level `material = ...`, so every inline material block starts
// from the initial all-zero default and spells out all its fields. A named material is
// declared inline at its first use and referred to by name afterwards.
#include "io/ray_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "core/file_util.h"

namespace lc::io {

namespace {

namespace fs = std::filesystem;

const char* kindWord(ShapeKind k) {
  switch (k) {
    case ShapeKind::Sphere: return "sphere";
    case ShapeKind::Box: return "box";
    case ShapeKind::Square: return "square";
    case ShapeKind::Cylinder: return "cylinder";
    case ShapeKind::Cone: return "cone";
    case ShapeKind::Mesh: break;
  }
  return "trimesh";
}

// Quoted strings cannot contain '"' or line breaks; names are made writable.
std::string sanitizeName(const std::string& s) {
  std::string r = s;
  for (char& c : r)
    if (c == '"' || c == '\n' || c == '\r') c = '_';
  return r;
}

class Writer {
 public:
  Writer(const SceneDesc& scene, const RayWriteOptions& options) : s_(scene), opt_(options) {}

  std::string run() {
    out_ = "SBT-raytracer 1.0\n";
    if (s_.hasCamera) camera();
    if (!isBlack(s_.ambient)) {
      out_ += "\nambient_light {\n  colour = ";
      vec(s_.ambient);
      out_ += ";\n}\n";
    }
    for (const LightDesc& l : s_.lights) light(l);
    if (s_.instantRadiosity) instantRadiosity(*s_.instantRadiosity);
    for (const EnvironmentDesc& e : s_.environments) environment(e);
    for (const ObjectDesc& o : s_.objects) object(o);
    return std::move(out_);
  }

 private:
  // ---- numbers --------------------------------------------------------------------------
  // Floats in the shortest form that reads back as the same float (0.63f -> "0.63", not
  // %.9g's "0.629999995"). The reader parses a double and narrows it to float, which can
  // round differently from a direct decimal -> float conversion right at a tie, so each
  // candidate is checked through that same path; 17 digits of the double always read back.
  void fnum(float v) {
    if (!std::isfinite(v)) throw Error("cannot write a non-finite number (" + std::to_string(v) + ") as .ray");
    char buf[40];
    auto readsBack = [&](const char* end) {
      double d = 0;
      auto [p, ec] = std::from_chars(buf, end, d);
      float f = float(d);
      return ec == std::errc() && p == end && std::memcmp(&f, &v, sizeof f) == 0;
    };
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    if (ec == std::errc() && readsBack(end)) {
      out_.append(buf, end);
      return;
    }
    for (const char* fmt : {"%.9g", "%.17g"}) {
      int n = std::snprintf(buf, sizeof buf, fmt, double(v));
      if (n > 0 && n < int(sizeof buf) && readsBack(buf + n)) break;
    }
    out_ += buf;
  }
  // Doubles (transform matrices) in the shortest form that reads back as the same double.
  void dnum(double v) {
    if (!std::isfinite(v)) throw Error("cannot write a non-finite number (" + std::to_string(v) + ") as .ray");
    char buf[40];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    if (ec != std::errc()) throw Error("cannot write the number " + std::to_string(v) + " as .ray");
    out_.append(buf, end);
  }
  void vec(const Vec3& v) {
    out_ += '(';
    fnum(v.x);
    out_ += ", ";
    fnum(v.y);
    out_ += ", ";
    fnum(v.z);
    out_ += ')';
  }
  void quoted(const std::string& s) {
    out_ += '"';
    out_ += s;
    out_ += '"';
  }
  void line(const std::string& indent, const char* key, const Vec3& v) {
    out_ += indent + key + " = ";
    vec(v);
    out_ += ";\n";
  }
  void line(const std::string& indent, const char* key, float v) {
    out_ += indent + key + " = ";
    fnum(v);
    out_ += ";\n";
  }

  // Texture paths relative to opt_.relativeTo (the directory the .ray file will be in).
  std::string texturePath(const std::string& p) const {
    if (p.find('"') != std::string::npos || p.find('\n') != std::string::npos)
      throw Error("cannot write texture path '" + p + "' in a .ray file (it contains '\"' or a newline)");
    if (opt_.relativeTo.empty()) return p;
    std::error_code ec;
    fs::path a = fs::absolute(p, ec).lexically_normal();
    fs::path b = fs::absolute(opt_.relativeTo, ec).lexically_normal();
    fs::path r = a.lexically_relative(b);
    return r.empty() ? p : r.generic_string();
  }
  void map(const TextureRef& t) {
    out_ += "map(";
    quoted(texturePath(t.path));
    out_ += ")";
  }
  void colour(const std::string& indent, const char* key, const ColorParam& c) {
    out_ += indent + key + " = ";
    if (c.map) map(*c.map);
    else vec(c.value);
    out_ += ";\n";
  }
  void scalar(const std::string& indent, const char* key, const ScalarParam& s) {
    out_ += indent + key + " = ";
    if (s.map) map(*s.map);
    else fnum(s.value);
    out_ += ";\n";
  }

  // ---- camera, lights ----------------------------------------------------------------------
  void camera() {
    const CameraDesc& c = s_.camera;
    out_ += "\ncamera {\n";
    line("  ", "position", c.position);
    line("  ", "viewdir", c.viewDir);
    line("  ", "updir", c.upDir);
    line("  ", "fov", c.fovDegrees);
    if (c.aspectRatio) line("  ", "aspectratio", *c.aspectRatio);
    out_ += "}\n";
  }

  void attenuation(float a, float b, float c, const std::string& indent) {
    line(indent, "constant_attenuation_coeff", a);
    line(indent, "linear_attenuation_coeff", b);
    line(indent, "quadratic_attenuation_coeff", c);
  }

  void light(const LightDesc& l) {
    switch (l.kind) {
      case LightKind::Point:
        out_ += "\npoint_light {\n";
        line("  ", "position", l.position);
        line("  ", "colour", l.colour);
        attenuation(l.attenConstant, l.attenLinear, l.attenQuadratic, "  ");
        break;
      case LightKind::Directional:
        out_ += "\ndirectional_light {\n";
        line("  ", "direction", l.direction);
        line("  ", "colour", l.colour);
        break;
      case LightKind::Spot:
        out_ += "\nspot_light {\n";
        line("  ", "position", l.position);
        line("  ", "direction", l.direction);
        line("  ", "colour", l.colour);
        attenuation(l.attenConstant, l.attenLinear, l.attenQuadratic, "  ");
        line("  ", "exponent", l.exponent);
        line("  ", "cutoff", l.cutoffDegrees);
        if (l.coneAngleDegrees) line("  ", "cone_angle", *l.coneAngleDegrees);
        line("  ", "penumbra", l.penumbraDegrees);
        if (std::isfinite(l.cutoffDistance)) line("  ", "cutoff_distance", l.cutoffDistance);
        break;
    }
    out_ += "}\n";
  }

  void environment(const EnvironmentDesc& e) {
    if (e.kind == EnvironmentKind::Map) {
      out_ += "\nenvironment_light {\n";
      if (e.map) {
        out_ += "  map = ";
        quoted(texturePath(e.map->path));
        out_ += ";\n";
      }
      line("  ", "colour", e.colour);
      line("  ", "intensity", e.intensity);
      line("  ", "up", e.up);
      line("  ", "rotate", e.rotateDegrees);
    } else {
      out_ += "\nsun_sky_light {\n";
      line("  ", "direction", e.sunDirection);
      line("  ", "turbidity", e.turbidity);
      line("  ", "intensity", e.intensity);
      line("  ", "ground", e.ground);
    }
    out_ += "  lights = " + std::to_string(e.lights) + ";\n";
    out_ += std::string("  visible = ") + (e.visible ? "true" : "false") + ";\n}\n";
  }

  void instantRadiosity(const InstantRadiosityDesc& ir) {
    out_ += "\ninstant_radiosity {\n";
    if (ir.vpls) out_ += "  vpls = " + std::to_string(*ir.vpls) + ";\n";
    if (ir.bounces) out_ += "  bounces = " + std::to_string(*ir.bounces) + ";\n";
    if (ir.normalize) {
      out_ += "  normalize = ";
      quoted(vplNormalizeName(*ir.normalize));
      out_ += ";\n";
    }
    if (ir.clamp) line("  ", "clamp", *ir.clamp);
    if (ir.seed) out_ += "  seed = " + std::to_string(*ir.seed) + ";\n";
    if (ir.caustics) out_ += "  caustics = " + std::to_string(*ir.caustics) + ";\n";
    if (ir.causticLights) {
      out_ += "  caustic_lights = ";
      quoted(causticLightKindName(*ir.causticLights));
      out_ += ";\n";
    }
    out_ += "}\n";
  }

  // ---- materials ----------------------------------------------------------------------------
  const MaterialDesc& materialAt(int index) const {
    if (index < 0 || size_t(index) >= s_.materials.size())
      throw Error("cannot write material index " + std::to_string(index) + " (the scene has " +
                  std::to_string(s_.materials.size()) + " materials)");
    return s_.materials[size_t(index)];
  }

  // A material value: its name when already declared, else an inline block.
  void materialValue(int index, const std::string& indent) {
    const MaterialDesc& m = materialAt(index);
    auto it = declared_.find(index);
    if (it != declared_.end()) {
      quoted(it->second);
      return;
    }
    std::string name = sanitizeName(m.name);
    bool declare = !name.empty() && usedNames_.insert(name).second;
    std::string in = indent + "  ";
    out_ += "{\n";
    if (declare) {
      out_ += in + "name = ";
      quoted(name);
      out_ += ";\n";
      declared_[index] = name;
    }
    if (m.emissiveSet || m.emissive.map || !isBlack(m.emissive.value)) colour(in, "emissive", m.emissive);
    colour(in, "ambient", m.ambient);
    colour(in, "diffuse", m.diffuse);
    colour(in, "specular", m.specular);
    colour(in, "reflective", m.reflective);
    colour(in, "transmissive", m.transmissive);
    scalar(in, "shininess", m.shininess);
    scalar(in, "index", m.index);
    if (m.luminosity) {
      const LuminosityDesc& l = *m.luminosity;
      std::string in2 = in + "  ";
      out_ += in + "luminosity = {\n";
      if (l.colourFromDiffuse) out_ += in2 + "colour = texture;\n";
      else colour(in2, "colour", l.colour);
      line(in2, "intensity", l.intensity);
      if (l.perArea) out_ += in2 + "per_area = true;\n";
      line(in2, "density", l.density);
      attenuation(l.attenConstant, l.attenLinear, l.attenQuadratic, in2);
      out_ += in + "};\n";
    }
    out_ += indent + "}";
  }

  // ---- objects ------------------------------------------------------------------------------
  void openTransform(const Mat4& m) {
    out_ += "\ntransform(";
    for (int r = 0; r < 4; ++r) {
      out_ += '(';
      for (int c = 0; c < 4; ++c) {
        if (c) out_ += ", ";
        dnum(m.m[size_t(r)][size_t(c)]);
      }
      out_ += r < 3 ? "), " : "),\n";
    }
  }

  void commonAttributes(const ObjectDesc& o, int material, const std::string& in) {
    out_ += in + "material = ";
    materialValue(material, in);
    out_ += ";\n";
    if (!o.name.empty()) {
      out_ += in + "name = ";
      quoted(sanitizeName(o.name));
      out_ += ";\n";
    }
  }

  void object(const ObjectDesc& o) {
    if (o.kind == ShapeKind::Mesh) return meshObject(o);
    openTransform(o.transform);
    const std::string in = "    ";
    out_ += std::string("  ") + kindWord(o.kind) + " {\n";
    commonAttributes(o, o.material, in);
    if (o.kind == ShapeKind::Cylinder || o.kind == ShapeKind::Cone)
      out_ += in + "capped = " + (o.capped ? "true" : "false") + ";\n";
    if (o.kind == ShapeKind::Cone) {
      line(in, "height", o.height);
      line(in, "bottom_radius", o.bottomRadius);
      line(in, "top_radius", o.topRadius);
    }
    out_ += "  })\n";
  }

  void meshObject(const ObjectDesc& o) {
    if (o.mesh < 0 || size_t(o.mesh) >= s_.meshes.size())
      throw Error("cannot write mesh index " + std::to_string(o.mesh) + " (the scene has " +
                  std::to_string(s_.meshes.size()) + " meshes)");
    const MeshDesc& mesh = s_.meshes[size_t(o.mesh)];
    if (mesh.triangleMaterials.empty()) return trimesh(o, mesh, o.material);
    if (mesh.triangleMaterials.size() != mesh.triangles.size())
      throw Error("cannot write a mesh with " + std::to_string(mesh.triangles.size()) + " triangles but " +
                  std::to_string(mesh.triangleMaterials.size()) + " triangle materials");
    // .ray has no per-face materials: one trimesh per material, with only the vertices it uses.
    std::map<int, std::vector<size_t>> byMaterial;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) byMaterial[mesh.triangleMaterials[t]].push_back(t);
    for (const auto& [mat, tris] : byMaterial) {
      MeshDesc sub;
      sub.genNormals = mesh.genNormals;
      std::unordered_map<int, int> remap;
      for (size_t t : tris) {
        std::array<int, 3> tri{};
        for (int k = 0; k < 3; ++k) {
          int v = mesh.triangles[t][size_t(k)];
          if (v < 0 || size_t(v) >= mesh.points.size())
            throw Error("cannot write a mesh whose triangle refers to vertex " + std::to_string(v));
          auto [it, fresh] = remap.emplace(v, int(sub.points.size()));
          if (fresh) {
            sub.points.push_back(mesh.points[size_t(v)]);
            if (mesh.normals.size() == mesh.points.size()) sub.normals.push_back(mesh.normals[size_t(v)]);
            if (mesh.uvs.size() == mesh.points.size()) sub.uvs.push_back(mesh.uvs[size_t(v)]);
            if (mesh.vertexMaterials.size() == mesh.points.size())
              sub.vertexMaterials.push_back(mesh.vertexMaterials[size_t(v)]);
          }
          tri[size_t(k)] = it->second;
        }
        sub.triangles.push_back(tri);
      }
      trimesh(o, sub, mat);
    }
  }

  void trimesh(const ObjectDesc& o, const MeshDesc& mesh, int material) {
    const bool bake = opt_.bakeTransforms;
    // Baking the identity copies the data exactly (obj2ray): renormalising the normals
    // would move them by an ulp and the .ray would no longer render the same image.
    const bool identity = o.transform.m == Mat4::identity().m;
    Mat4 inv = Mat4::identity();
    if (bake && !o.transform.inverseAffine(inv))
      throw Error("cannot bake a singular transform into a mesh");
    std::string in = bake ? "  " : "    ";
    if (bake) {
      out_ += "\ntrimesh {\n";
    } else {
      openTransform(o.transform);
      out_ += "  trimesh {\n";
    }
    commonAttributes(o, material, in);
    const size_t n = mesh.points.size();
    auto vecList = [&](const char* key, size_t count, const std::function<Vec3(size_t)>& at) {
      out_ += in + key + " = (";
      for (size_t i = 0; i < count; ++i) {
        out_ += i ? ",\n" : "\n";
        out_ += in + "  ";
        vec(at(i));
      }
      out_ += ");\n";
    };
    vecList("points", n, [&](size_t i) {
      return bake && !identity ? o.transform.point(mesh.points[i]) : mesh.points[i];
    });
    out_ += in + "faces = (";
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      out_ += i ? ",\n" : "\n";
      out_ += in + "  (" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
    }
    out_ += ");\n";
    if (!mesh.normals.empty())
      vecList("normals", mesh.normals.size(), [&](size_t i) {
        return bake && !identity ? normalize(inv.normalFromInverse(mesh.normals[i])) : mesh.normals[i];
      });
    if (!mesh.uvs.empty()) {
      out_ += in + "texture_uv = (";
      for (size_t i = 0; i < mesh.uvs.size(); ++i) {
        out_ += i ? ",\n" : "\n";
        out_ += in + "  (";
        fnum(mesh.uvs[i].x);
        out_ += ", ";
        fnum(mesh.uvs[i].y);
        out_ += ")";
      }
      out_ += ");\n";
    }
    if (!mesh.vertexMaterials.empty()) {
      out_ += in + "materials = (";
      for (size_t i = 0; i < mesh.vertexMaterials.size(); ++i) {
        out_ += i ? ",\n" : "\n";
        out_ += in + "  ";
        materialValue(mesh.vertexMaterials[i], in + "  ");
      }
      out_ += ");\n";
    }
    if (mesh.genNormals) out_ += in + "gennormals;\n";
    out_ += bake ? "}\n" : "  })\n";
  }

  const SceneDesc& s_;
  const RayWriteOptions& opt_;
  std::string out_;
  std::unordered_map<int, std::string> declared_;  // material index -> the name it was declared as
  std::unordered_set<std::string> usedNames_;
};

}  // namespace

std::string writeRayString(const SceneDesc& scene, const RayWriteOptions& options) {
  return Writer(scene, options).run();
}

void writeRayFile(const std::string& path, const SceneDesc& scene, const RayWriteOptions& options) {
  std::string text = writeRayString(scene, options);  // fails before any file is touched
  writeFileAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("cannot write '" + path + "'");
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) throw Error("cannot write '" + path + "'");
  });
}

}  // namespace lc::io
