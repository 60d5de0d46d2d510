// cellctl: the cell's command line. Exit codes: 0 done, 1 the job could not be done
// (e.g. no complete plan), 2 bad input or usage.

#include <iostream>

#include <CLI/CLI.hpp>

#include "deploy/cellctl/cell_commands.hpp"
#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/describe_command.hpp"
#include "deploy/cellctl/pki_command.hpp"
#include "deploy/cellctl/plan_command.hpp"
#include "deploy/cellctl/quote_command.hpp"
#include "twin/model/source_ref.hpp"

int main(int argc, char** argv) {
  CLI::App app{"cellctl: plan and run product orders on an agile assembly cell"};
  app.require_subcommand(1);
  int exit_code = 0;
  cellctl::add_describe_command(app, exit_code);
  cellctl::add_plan_command(app, exit_code);
  cellctl::add_cell_commands(app, exit_code);
  cellctl::add_pki_command(app, exit_code);
  cellctl::add_quote_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const cellctl::ConfigError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const twin::DescriptionError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
  return exit_code;
}
