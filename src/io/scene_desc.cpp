#include "io/scene_desc.h"

namespace lc::io {

const char* vplNormalizeName(VplNormalize v) {
  for (const auto& [value, name] : kVplNormalizeNames)
    if (value == v) return name;
  return "?";
}

std::optional<VplNormalize> findVplNormalize(std::string_view name) {
  for (const auto& [value, n] : kVplNormalizeNames)
    if (name == n) return value;
  return std::nullopt;
}

VplNormalize parseVplNormalize(const std::string& name) {
  if (std::optional<VplNormalize> v = findVplNormalize(name)) return *v;
  throw Error("unknown VPL normalisation '" + name + "' (use " + vplNormalizeChoices() + ")");
}

std::string vplNormalizeChoices(const char* quote) {
  std::string s;
  for (const auto& [value, name] : kVplNormalizeNames)
    s += (s.empty() ? "" : " or ") + std::string(quote) + name + quote;
  return s;
}

}  // namespace lc::io
