#pragma once
// Reading a mesh file's triangles with Assimp. Assimp is a large library that takes several
// milliseconds to load into a process, and a process that finds its meshes in the disk cache
// (mesh_disk_cache.hpp) never asks it: it lives in a module of its own
// (libsim_mesh_import.so, beside the executables), opened the first time a file is read.

#include <filesystem>

#include "sim/mesh/triangle_mesh.hpp"

namespace sim {

// The file's triangles as written (corners welded where they coincide, every object a piece
// of its own), its vertices, pieces and bounds filled in `mesh`. Throws MeshError when the file
// cannot be read or the module cannot be opened.
void import_mesh(const std::filesystem::path& file, TriangleMesh& mesh);

}  // namespace sim
