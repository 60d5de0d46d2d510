#pragma once
// cellctl quote PRODUCT.aml --cell a.yaml --cell b.yaml ... --client ID: the OEM's side of
// quotes (docs/quotes.md). Asks every cell's order desk at once, each on its own DDS domain,
// for a quote (virtual assembly only), prints the answers side by side with the best by time
// and by cost marked, and writes them as JSON.

#include <CLI/CLI.hpp>

namespace cellctl {

void add_quote_command(CLI::App& app, int& exit_code);

}  // namespace cellctl
