// `saarcor`: the command-line front end. This is the only translation unit that includes CLI11
// (it costs ~10 s of compile time per TU); each subcommand's work lives in its own file and is
// reached through a plain options struct.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "testbench/version.h"
// [subcommand headers]

int main(int argc, char** argv) {
  CLI::App app{"saarcor: cycle-level, bit-accurate model of the SaarCOR dynamic ray tracing "
               "pipeline (Schmittler, Woop et al., 2004)"};
  app.set_version_flag("--version", std::string("saarcor ") + saarcor::kVersion);
  app.require_subcommand(1);
  int status = 0;

  // [subcommands]

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    // Every bad input ends here: one line naming the problem, non-zero exit.
    std::fprintf(stderr, "saarcor: error: %s\n", e.what());
    return 1;
  }
  return status;
}
