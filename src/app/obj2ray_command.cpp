// `lightcuts obj2ray`: an OBJ/MTL model written as an equivalent .ray scene.
#include <fmt/format.h>

#include <filesystem>

#include "app/commands.h"
#include "core/file_util.h"
#include "io/obj_loader.h"

namespace lc::app {

// obj2ray's output when -o is not given: the input with its extension replaced by .ray, in
// the input's folder ("models/cube.obj" -> "models/cube.ray", "cube" -> "cube.ray").
std::string defaultRayOutput(const std::string& input) {
  return std::filesystem::path(input).replace_extension(".ray").string();
}

void addObj2RayCommand(CLI::App& app) {
  auto in = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  CLI::App* c = app.add_subcommand("obj2ray", "Convert an OBJ/MTL model to an equivalent .ray scene");
  c->add_option("input", *in, "OBJ file")->required();
  c->add_option("-o,--output", *out,
                "Output .ray file (default: the input with its extension replaced by .ray, in the input's folder: "
                "model.obj -> model.ray)");
  c->callback([in, out] {
    if (parseOnly()) return;
    if (out->empty()) {
      *out = defaultRayOutput(*in);
      // A default that would overwrite the input (IN is already .ray) is refused, not written.
      checkDistinctPaths({{*in, "the input OBJ"}, {*out, "the default output (the input with .ray; choose another with -o)"}});
    } else {
      checkDistinctPaths({{*in, "the input OBJ"}, {*out, "-o"}});
    }
    io::writeRayFromObj(*in, *out, Limits{});
    fmt::print("wrote {}\n", *out);
    exitStatus() = 0;
  });
}

}  // namespace lc::app
