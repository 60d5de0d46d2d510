// libFuzzer target: a part's mesh file (Wavefront OBJ, what the products ship) through
// Assimp and the checks of sim::load_mesh. Refusals are exceptions; no input may crash.
//   fuzz_mesh CORPUS_DIR [seed dirs...] -max_total_time=60

#include <unistd.h>

#include <cstdint>
#include <exception>
#include <fstream>
#include <string>

#include "sim/mesh/triangle_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string file = "/tmp/fuzz-mesh-" + std::to_string(::getpid()) + ".obj";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    sim::load_mesh(file);
  } catch (const std::exception&) {
  }
  return 0;
}
