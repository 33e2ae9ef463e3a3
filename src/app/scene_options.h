// Command-line options shared by the commands that load a scene (render, info).
#pragma once

#include <CLI/CLI.hpp>

#include "app/scene_loader.h"

namespace lc::app {

void addSceneOptions(CLI::App& c, LoadOptions& o);

}  // namespace lc::app
