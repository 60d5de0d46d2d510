#pragma once
// What both cellctl executables do with their command line: parse it, run the subcommand,
// and turn what went wrong into an exit code (0 done, 1 the job could not be done, 2 bad input
// or usage) with the error on stderr.

#include <CLI/CLI.hpp>

namespace cellctl {

// What `cellctl --help` says the program is, in both executables.
inline constexpr const char* kDescription = "cellctl: plan and run product orders on an agile assembly cell";

int run_app(CLI::App& app, int argc, char** argv, const int& exit_code);

}  // namespace cellctl
