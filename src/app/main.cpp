// lightcuts: a ray tracer for scenes lit by many lights. See README.md.
#include <fmt/format.h>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "core/error.h"

namespace lc::app {
int& exitStatus() {
  static int status = 0;
  return status;
}
}  // namespace lc::app

int main(int argc, char** argv) {
  CLI::App app{"lightcuts: a ray tracer for the SBT .ray format that renders thousands to millions of lights "
               "with Lightcuts (Walter et al. 2005), the course project's cuts, or brute force"};
  // At most one subcommand; none prints the help (below).
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "lightcuts 0.1.0");
  lc::app::addRenderCommand(app);
  lc::app::addInfoCommand(app);
  lc::app::addCompareCommand(app);
  lc::app::addObj2RayCommand(app);
  lc::app::addSkyCommand(app);
  try {
    app.parse(argc, argv);
    // No subcommand: the help, as for --help (stdout, status 0), rather than CLI11's
    // "A subcommand is required" that leaves the user to guess the commands.
    if (app.get_subcommands().empty()) throw CLI::CallForHelp();
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const lc::Error& e) {
    fmt::print(stderr, "lightcuts: {}\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "lightcuts: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "lightcuts: internal error: {}\n", e.what());
    return 2;
  }
  return lc::app::exitStatus();
}
