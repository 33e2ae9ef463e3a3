// The CLI's subcommands. Each returns the process exit status; user errors are thrown as
// lc::Error and turned into "lightcuts: <message>" with status 1 by main().
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lc::app {

void addRenderCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addObj2RayCommand(CLI::App& app);
void addSkyCommand(CLI::App& app);
// Every command above, and the top level's rules (main.cpp and the CLI fuzz target).
void addCommands(CLI::App& app);

// When set, the commands parse and check their arguments but do not run (the CLI fuzz
// target): their options stay bound to state their callbacks own.
bool& parseOnly();

// Exit status of the subcommand that ran (set by its callback).
int& exitStatus();

// The command line as given ("lightcuts render scene.ray -o 'my out.png'", arguments
// shell-quoted where needed), set by main() for the images' metadata.
std::string& commandLine();

}  // namespace lc::app
