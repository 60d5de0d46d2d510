#include "deploy/cellctl/describe_command.hpp"

#include <iostream>
#include <memory>

#include "deploy/cellctl/product_report.hpp"
#include "twin/geometry/product_loader.hpp"

namespace cellctl {

void add_describe_command(CLI::App& app, int& exit_code) {
  struct Options {
    std::string product;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("describe", "Read a product description and show the finished product");
  cmd->add_option("PRODUCT", options->product, "AutomationML file (.aml)")->required();
  cmd->add_flag("--json", options->json, "Print a JSON document instead of tables");
  cmd->callback([options, &exit_code] {
    sim::MeshCache meshes;
    const twin::LoadedProduct loaded = twin::load_product(options->product, meshes);
    // Overlaps are findings for the designer, not errors: the exit code stays 0.
    const twin::InterferenceCheck check = twin::find_interferences(loaded);
    if (options->json) {
      std::cout << product_json(loaded, check).dump(2) << '\n';
    } else {
      print_product_table(loaded, check, std::cout);
    }
    exit_code = 0;
  });
}

}  // namespace cellctl
