// Command-line options shared by the commands that load a scene (render, info).
#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "app/scene_loader.h"

namespace lc::app {

void addSceneOptions(CLI::App& c, LoadOptions& o);

// An on/off option (--gi, --visibility-probes): a bool, spelt "on" or "off" on the command
// line, in the help and in --stats; checked here, once.
CLI::Option* addSwitch(CLI::App& c, const std::string& name, bool& value, const std::string& help);
const char* switchName(bool on);  // "on" | "off"

}  // namespace lc::app
