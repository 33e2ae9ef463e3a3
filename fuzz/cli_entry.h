// The CLI fuzz target's entry point (fuzz/cli_fuzz.cpp), shared with the regression test
// (src/app/fuzz_regression_test.cpp). The input is split at newlines into at most 32
// arguments after "lightcuts"; the whole CLI as main() builds it (every command, option,
// validator and option callback) parses them, with app::parseOnly() set so that the
// commands do not run: nothing renders or writes. CLI::ParseError (main() turns it into a usage message) and
// lc::Error are clean refusals; anything else is a finding.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"

namespace lc::fuzz {

inline void parseArgs(const uint8_t* data, size_t size) {
  std::vector<std::string> args{"lightcuts"};
  std::string cur;
  for (size_t i = 0; i < size && args.size() < 33; ++i) {
    if (data[i] == '\n') {
      args.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(char(data[i]));
    }
  }
  if (!cur.empty() && args.size() < 33) args.push_back(cur);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());

  CLI::App app{"lightcuts"};
  app::addCommands(app);
  // Not by replacing the commands' callbacks: they own the state their options write to.
  struct ParseOnly {
    ParseOnly() { app::parseOnly() = true; }
    ~ParseOnly() { app::parseOnly() = false; }
  } parseOnly;
  try {
    app.parse(int(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
  }
}

}  // namespace lc::fuzz
