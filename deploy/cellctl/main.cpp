// cellctl-cell: every cellctl command (`cellctl` runs describe and plan itself and hands the
// others here: front_main.cpp). Exit codes: 0 done, 1 the job could not be done (e.g. no
// complete plan), 2 bad input or usage.

#include <CLI/CLI.hpp>

#include "deploy/cellctl/cell_commands.hpp"
#include "deploy/cellctl/describe_command.hpp"
#include "deploy/cellctl/pki_command.hpp"
#include "deploy/cellctl/plan_command.hpp"
#include "deploy/cellctl/quote_command.hpp"
#include "deploy/cellctl/run_app.hpp"
#include "twin/planning/work_memory.hpp"

int main(int argc, char** argv) {
  twin::keep_work_memory();
  CLI::App app{cellctl::kDescription};
  app.require_subcommand(1);
  int exit_code = 0;
  cellctl::add_describe_command(app, exit_code);
  cellctl::add_plan_command(app, exit_code);
  cellctl::add_cell_commands(app, exit_code);
  cellctl::add_pki_command(app, exit_code);
  cellctl::add_quote_command(app, exit_code);
  return cellctl::run_app(app, argc, argv, exit_code);
}
