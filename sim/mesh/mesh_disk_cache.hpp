#pragma once
// Loaded meshes on disk, by the SHA-256 of the file's bytes and the scale: a second order of
// the same product (another twin process, another `cellctl plan`) reads the repaired mesh
// back instead of parsing the CAD export again. Entries are written whole (a temporary file
// renamed into place); one that is short, of another version or inconsistent is ignored and
// written anew. The folder is $AGILE_CELL_MESH_CACHE, else $XDG_CACHE_HOME/agile-cell/meshes,
// else ~/.cache/agile-cell/meshes; AGILE_CELL_MESH_CACHE=off turns it off.

#include <filesystem>
#include <memory>
#include <optional>

#include "sim/mesh/triangle_mesh.hpp"

namespace sim {

class MeshDiskCache {
 public:
  explicit MeshDiskCache(std::filesystem::path folder) : folder_(std::move(folder)) {}
  // The folder the environment names, or nothing when the cache is off.
  static std::optional<std::filesystem::path> folder_from_environment();

  // The mesh of `file` at `scale`: from the cache when it holds this content, else loaded
  // (load_mesh) and stored. Throws MeshError as load_mesh does.
  std::shared_ptr<const TriangleMesh> load(const std::filesystem::path& file, double scale);

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
};

}  // namespace sim
