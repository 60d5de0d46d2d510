// cellctl: the cell's command line. `describe` and `plan` run in this process, which loads
// no DDS, OMPL or SQLite: Debian links every library BIND_NOW, and loading the cell's (Fast
// DDS alone 14 ms) is time a plan need not spend (docs/performance.md). Every
// other command, `--help` and `plan --path ompl` run in cellctl-cell beside it, which has
// them all (exec: the same process, pid and arguments). Exit codes: 0 done, 1 the job could
// not be done (e.g. no complete plan), 2 bad input or usage.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "deploy/cellctl/describe_command.hpp"
#include "deploy/cellctl/plan_command.hpp"
#include "deploy/cellctl/processes.hpp"
#include "deploy/cellctl/run_app.hpp"
#include "twin/planning/work_memory.hpp"

namespace {

bool runs_here(int argc, char** argv) {
  if (argc < 2) return false;
  const std::string command = argv[1];
  const bool ompl = std::any_of(argv + 2, argv + argc, [](const char* a) {
    return std::strcmp(a, "ompl") == 0 || std::strcmp(a, "--path=ompl") == 0;
  });
  return command == "describe" || (command == "plan" && !ompl);
}

}  // namespace

int main(int argc, char** argv) {
  if (!runs_here(argc, argv)) {
    const std::string full = cellctl::executable_dir() + "/cellctl-cell";
    ::execv(full.c_str(), argv);
    std::cerr << "error: cannot run " << full << ": " << std::strerror(errno) << '\n';
    return 1;
  }
  twin::keep_work_memory();
  CLI::App app{cellctl::kDescription};
  app.require_subcommand(1);
  int exit_code = 0;
  cellctl::add_describe_command(app, exit_code);
  cellctl::add_plan_command(app, exit_code);
  return cellctl::run_app(app, argc, argv, exit_code);
}
