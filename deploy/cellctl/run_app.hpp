#pragma once
// What both cellctl executables do with their command line: parse it, run the subcommand,
// and turn what went wrong into an exit code (0 done, 1 the job could not be done, 2 bad input
// or usage) with the error on stderr.

#include <CLI/CLI.hpp>

namespace cellctl {

int run_app(CLI::App& app, int argc, char** argv, const int& exit_code);

}  // namespace cellctl
