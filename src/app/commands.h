// The CLI's subcommands. Each returns the process exit status; user errors are thrown as
// lc::Error and turned into "lightcuts: <message>" with status 1 by main().
#pragma once

#include <CLI/CLI.hpp>

namespace lc::app {

void addRenderCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addObj2RayCommand(CLI::App& app);
void addSkyCommand(CLI::App& app);

// Exit status of the subcommand that ran (set by its callback).
int& exitStatus();

}  // namespace lc::app
