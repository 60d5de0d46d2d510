#pragma once
// `cellctl pki init DIR` and `cellctl pki issue DIR NAME`: the cell's DDS-Security files
// (docs/security.md).

#include <CLI/CLI.hpp>

namespace cellctl {

void add_pki_command(CLI::App& app, int& exit_code);

}  // namespace cellctl
