#pragma once

#include <CLI/CLI.hpp>

namespace cellctl {

// cellctl up [CELL.yaml]               starts and supervises the cell until `down` or Ctrl-C
// cellctl submit PRODUCT.aml           spawns a twin for the order and follows it to its end
// cellctl status                       resources (alive, reserved by) and orders
// cellctl down                         stops the cell `up` started
// cellctl run PRODUCT.aml [--events F] up, submit, down in one go
void add_cell_commands(CLI::App& app, int& exit_code);

}  // namespace cellctl
