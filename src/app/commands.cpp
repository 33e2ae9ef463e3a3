// The command set of the `lightcuts` binary, built once for main() and the CLI fuzz target.
#include "app/commands.h"

namespace lc::app {

int& exitStatus() {
  static int status = 0;
  return status;
}

bool& parseOnly() {
  static bool only = false;
  return only;
}

std::string& commandLine() {
  static std::string line;
  return line;
}

void addCommands(CLI::App& app) {
  // At most one subcommand; none prints the help (main.cpp).
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "lightcuts " LC_VERSION);
  // --help-all: every subcommand's options too (the man page is made from it).
  app.set_help_all_flag("--help-all", "Print this help with every subcommand's options, and exit");
  addRenderCommand(app);
  addInfoCommand(app);
  addCompareCommand(app);
  addObj2RayCommand(app);
  addSkyCommand(app);
}

}  // namespace lc::app
