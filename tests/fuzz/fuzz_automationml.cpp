// libFuzzer target: an AutomationML file as an OEM might send it, through the whole reading
// of a product (XML, CAEX, the product model, placement). Any input may be refused with an
// exception; none may crash, hang or leak.
//   fuzz_automationml CORPUS_DIR [seed dirs...] -max_total_time=60

#include <unistd.h>

#include <cstdint>
#include <exception>
#include <fstream>
#include <string>

#include "sim/mesh/triangle_mesh.hpp"
#include "twin/geometry/product_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The reader takes files (it names them in its messages): one per process, rewritten.
  static const std::string file = "/tmp/fuzz-automationml-" + std::to_string(::getpid()) + ".aml";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    sim::MeshCache meshes;
    twin::load_product(file, meshes);
  } catch (const std::exception&) {
    // Refused with a reason: what bad input must get.
  }
  return 0;
}
