#pragma once

#include <CLI/CLI.hpp>

namespace cellctl {

// cellctl describe PRODUCT.aml [--json]: the parts, links and final positions.
void add_describe_command(CLI::App& app, int& exit_code);

}  // namespace cellctl
