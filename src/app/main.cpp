// lightcuts: a ray tracer for scenes lit by many lights. See README.md.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <cstring>
#include <string>

#include "app/commands.h"
#include "app/warnings.h"
#include "core/error.h"

namespace lc::app {
namespace {
std::string shellQuote(const std::string& arg) {
  bool plain = !arg.empty();
  for (unsigned char c : arg) plain = plain && (std::isalnum(c) || std::strchr("_./=:,+-@%", c));
  if (plain) return arg;
  std::string q = "'";
  for (char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace
}  // namespace lc::app

int main(int argc, char** argv) {
  CLI::App app{"lightcuts: a ray tracer for the SBT .ray format that renders thousands to millions of lights "
               "with Lightcuts (Walter et al. 2005), the course project's cuts, or brute force"};
  lc::app::addCommands(app);
  std::string& line = lc::app::commandLine();
  line = "lightcuts";
  for (int i = 1; i < argc; ++i) line += " " + lc::app::shellQuote(argv[i]);
  try {
    app.parse(argc, argv);
    // No subcommand: the help, as for --help (stdout, status 0), rather than CLI11's
    // "A subcommand is required" that leaves the user to guess the commands.
    if (app.get_subcommands().empty()) throw CLI::CallForHelp();
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const lc::Error& e) {
    fmt::print(stderr, "lightcuts: {}\n", e.what());
    std::string hint = lc::app::hintForError(e.bare());
    if (!hint.empty()) lc::app::printHint(hint);
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
