// Placeholder until instant radiosity lands.
#include "lights/vpl.h"

#include "core/error.h"

namespace lc::lights {

VplNormalize parseVplNormalize(const std::string& s) {
  if (s == "power") return VplNormalize::Power;
  if (s == "object") return VplNormalize::Object;
  throw Error("unknown VPL normalisation '" + s + "' (use power or object)");
}

VplInfo addVpls(scene::Scene&, const VplOptions& options) {
  if (options.count > 0) throw Error("instant radiosity (VPLs) is not supported yet");
  return {};
}

}  // namespace lc::lights
