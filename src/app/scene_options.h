// Command-line options shared by the commands that load a scene (render, info).
#pragma once

#include <CLI/CLI.hpp>

#include <cstddef>
#include <string>

#include "app/scene_loader.h"
#include "core/enum_names.h"

namespace lc::app {

void addSceneOptions(CLI::App& c, LoadOptions& o);

// An option with named values (core/enum_names.h): checked against its table's
// spellings (aliases too; CLI11's message lists them), then `set` with the value they
// name. The help lists the names from the same table (enumHelp), so a value added there
// is accepted, parsed and documented here with no change.
template <typename E, size_t N, typename Set>
CLI::Option* addEnumOption(CLI::App& c, const std::string& name, const EnumName<E> (&names)[N], Set set,
                           const std::string& help) {
  return c
      .add_option_function<std::string>(
          name, [&names, set](const std::string& v) { set(parseEnum(names, v, "value")); }, help)
      ->check(CLI::IsMember(enumSpellings(names)));
}

// An on/off option (--gi, --visibility-probes): a bool, spelt "on" or "off" on the command
// line, in the help and in --stats; checked here, once.
CLI::Option* addSwitch(CLI::App& c, const std::string& name, bool& value, const std::string& help);
const char* switchName(bool on);  // "on" | "off"

}  // namespace lc::app
