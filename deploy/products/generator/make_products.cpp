// Writes the example products (AutomationML + OBJ meshes) into deploy/products/.
// Usage: make_products OUTPUT_DIR. The output is committed; rerun after changing a product.

#include <iostream>

#include "deploy/products/generator/products.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_products OUTPUT_DIR\n";
    return 2;
  }
  const std::filesystem::path out = argv[1];
  products::write_cranfield(out / "cranfield");
  products::write_lego_tower(out / "lego-tower");
  std::cout << "wrote " << (out / "cranfield").string() << " and " << (out / "lego-tower").string() << '\n';
  return 0;
}
