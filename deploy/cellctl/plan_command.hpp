#pragma once

#include <CLI/CLI.hpp>

namespace cellctl {

// cellctl plan PRODUCT.aml [--sequence paper|search] [--path linear|ompl] [--json FILE] [--gltf FILE] [--cell FILE]
void add_plan_command(CLI::App& app, int& exit_code);

}  // namespace cellctl
