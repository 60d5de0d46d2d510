// A generated wall of 1000 blocks: every block linked to its left and lower neighbour,
// so placement must walk 1000 parts and check some 1000 loops.

#include <fstream>

#include <unistd.h>

#include "tests/support/wall_product.hpp"
#include "tests/twin/test_support.hpp"


TEST_CASE("a generated product of 1000 parts is placed correctly", "[placement][scale]") {
  constexpr int columns = 25, rows = 40;
  const auto file = std::filesystem::temp_directory_path() / ("wall-" + std::to_string(::getpid()) + ".aml");
  std::ofstream(file) << test::wall_aml(columns, rows);
  const auto loaded = test::load(file);
  std::filesystem::remove(file);

  const auto& product = loaded.product;
  REQUIRE(product.parts().size() == 1000);
  CHECK(product.connections().size() == static_cast<std::size_t>((columns - 1) * rows + columns * (rows - 1)));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const auto name = "b-" + std::to_string(c) + "-" + std::to_string(r);
      const twin::Vec3 p = test::position_mm(product, name);
      if ((p - twin::Vec3(20.0 * c, 10.0 * r, 0)).norm() > 1e-6) {
        FAIL(name << " at " << p.transpose() << " mm");
      }
    }
  }
}
