#include "sim/mesh/mesh_disk_cache.hpp"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <sstream>
#include <unistd.h>

#include <nettle/sha2.h>

namespace sim {
namespace {

constexpr std::uint64_t kMagic = 0x31687365'4d6c6c65ULL;  // "ellMesh1"
// Raise it whenever loading gives other meshes (a new repair): older entries are then ignored.
constexpr std::uint32_t kVersion = 11;  // 4: the triangle tree (TriangleMesh::bvh_nodes); 5: COLLADA up axis kept; 6: convex meshes' coarse hulls; 7: coarse margins measured exactly (6 could hold 3e35 m); 8: objects joined where they are not convex pieces; 9: corners welded by position alone; 10: edges split at T-junctions; 11: missing triangles filled

// SHA-256 of the file's bytes, a NUL, then its extension (how it is read), in hex. Meshes come from
// OEMs (the order desk): with a hash one can collide on purpose (FNV-1a was used before), a
// crafted file could stand in for another client's cached mesh.
std::string content_hash(const std::string& bytes, const std::string& extension) {
  sha256_ctx context;
  sha256_init(&context);
  sha256_update(&context, bytes.size(), reinterpret_cast<const std::uint8_t*>(bytes.data()));
  sha256_update(&context, 1, reinterpret_cast<const std::uint8_t*>("\0"));
  sha256_update(&context, extension.size(), reinterpret_cast<const std::uint8_t*>(extension.data()));
  std::uint8_t digest[SHA256_DIGEST_SIZE];
  sha256_digest(&context, SHA256_DIGEST_SIZE, digest);
  static const char* const hex = "0123456789abcdef";
  std::string out;
  for (const std::uint8_t byte : digest) out += {hex[byte >> 4], hex[byte & 15]};
  return out;
}

template <class T>
void put(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

template <class T>
bool get(std::istream& in, T& value) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&value), sizeof value));
}

// `values` whole, in one read: a part of 50 000 triangles is 100 000 values.
template <class T>
bool get_all(std::istream& in, std::vector<T>& values) {
  return values.empty() ||
         static_cast<bool>(in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T))));
}

void write_entry(const std::filesystem::path& path, const TriangleMesh& m) {
  std::filesystem::create_directories(path.parent_path());
  static std::atomic<unsigned> written{0};  // two threads of a process write apart too
  const auto temporary = path.string() + ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(++written);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    put(out, kMagic);
    put(out, kVersion);
    put(out, static_cast<std::uint64_t>(m.vertices.size()));
    for (const auto& v : m.vertices) put(out, v);
    put(out, static_cast<std::uint64_t>(m.triangles.size()));
    for (const auto& t : m.triangles) put(out, t);
    const std::vector<std::vector<std::uint32_t>> coarse{m.coarse_corners};
    for (const auto* lists : {&m.pieces, &m.hull_corners, &coarse}) {
      put(out, static_cast<std::uint64_t>(lists->size()));
      for (const auto& list : *lists) {
        put(out, static_cast<std::uint64_t>(list.size()));
        out.write(reinterpret_cast<const char*>(list.data()), static_cast<std::streamsize>(list.size() * sizeof list[0]));
      }
    }
    put(out, m.coarse_margin);
    put(out, m.bounds.min());
    put(out, m.bounds.max());
    put(out, static_cast<std::uint8_t>(m.convex));
    for (std::size_t n : {m.repairs.degenerate, m.repairs.duplicate, m.repairs.flipped, m.repairs.t_junctions, m.repairs.missing_triangles,
                          m.repairs.open_edges,
                          m.repairs.non_manifold_edges, m.repairs.joined_objects}) {
      put(out, static_cast<std::uint64_t>(n));
    }
    put(out, static_cast<std::uint64_t>(m.bvh_nodes.size()));
    out.write(reinterpret_cast<const char*>(m.bvh_nodes.data()), static_cast<std::streamsize>(m.bvh_nodes.size()));
    if (!out) {
      std::filesystem::remove(temporary);
      return;
    }
  }
  std::filesystem::rename(temporary, path);  // whole or not at all
}

// The entry, or nothing when it is missing or not one this version wrote whole.
std::shared_ptr<TriangleMesh> read_entry(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  const auto size = std::filesystem::file_size(path);
  std::uint64_t magic = 0, n = 0;
  std::uint32_t version = 0;
  if (!get(in, magic) || magic != kMagic || !get(in, version) || version != kVersion) return nullptr;
  auto m = std::make_shared<TriangleMesh>();
  const auto count = [&](std::size_t each) { return get(in, n) && n * each <= size; };
  if (!count(sizeof(Eigen::Vector3d))) return nullptr;
  m->vertices.resize(n);
  if (!get_all(in, m->vertices)) return nullptr;
  for (const auto& v : m->vertices) {
    if (!v.allFinite()) return nullptr;
  }
  if (!count(sizeof(std::array<std::uint32_t, 3>))) return nullptr;
  m->triangles.resize(n);
  if (!get_all(in, m->triangles)) return nullptr;
  for (const auto& t : m->triangles) {
    if (t[0] >= m->vertices.size() || t[1] >= m->vertices.size() || t[2] >= m->vertices.size()) return nullptr;
  }
  std::vector<std::vector<std::uint32_t>> coarse;
  for (auto* lists : {&m->pieces, &m->hull_corners, &coarse}) {
    if (!count(sizeof(std::uint64_t))) return nullptr;
    lists->resize(n);
    for (auto& list : *lists) {
      if (!count(sizeof(std::uint32_t))) return nullptr;
      list.resize(n);
      if (!get_all(in, list)) return nullptr;
      for (std::uint32_t v : list) {
        if (v >= m->vertices.size()) return nullptr;
      }
    }
  }
  if (m->hull_corners.size() != m->pieces.size() || coarse.size() != 1) return nullptr;
  if (!coarse.front().empty() && m->pieces.size() != 1) return nullptr;  // a coarse hull is of one piece
  m->coarse_corners = std::move(coarse.front());
  if (!get(in, m->coarse_margin) || !std::isfinite(m->coarse_margin) || m->coarse_margin < 0) return nullptr;
  Eigen::Vector3d lo, hi;
  std::uint8_t convex = 0;
  if (!get(in, lo) || !get(in, hi) || !get(in, convex)) return nullptr;
  m->bounds = Eigen::AlignedBox3d(lo, hi);
  m->convex = convex != 0;
  for (std::size_t* r : {&m->repairs.degenerate, &m->repairs.duplicate, &m->repairs.flipped, &m->repairs.t_junctions, &m->repairs.missing_triangles,
                         &m->repairs.open_edges,
                         &m->repairs.non_manifold_edges, &m->repairs.joined_objects}) {
    if (!get(in, n)) return nullptr;
    *r = n;
  }
  // Read as it stands; whether it is a whole tree of these triangles is checked where it is used.
  if (!count(1)) return nullptr;
  m->bvh_nodes.resize(n);
  if (!get_all(in, m->bvh_nodes)) return nullptr;
  if (m->triangles.empty() || in.peek() != std::char_traits<char>::eof()) return nullptr;
  return m;
}

}  // namespace

std::optional<std::filesystem::path> MeshDiskCache::folder_from_environment() {
  const auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v ? v : "";
  };
  const std::string chosen = env("AGILE_CELL_MESH_CACHE");
  if (chosen == "off") return std::nullopt;
  if (!chosen.empty()) return std::filesystem::path(chosen);
  if (!env("XDG_CACHE_HOME").empty()) return std::filesystem::path(env("XDG_CACHE_HOME")) / "agile-cell" / "meshes";
  if (!env("HOME").empty()) return std::filesystem::path(env("HOME")) / ".cache" / "agile-cell" / "meshes";
  return std::nullopt;
}

std::shared_ptr<const TriangleMesh> MeshDiskCache::load(const std::filesystem::path& file, double scale) {
  std::ifstream in(file, std::ios::binary);
  std::error_code size_unknown;
  const auto size = std::filesystem::file_size(file, size_unknown);
  if (!in || size_unknown) return load_mesh(file, scale);  // says why it cannot be read
  std::string bytes(size, '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) return load_mesh(file, scale);
  std::ostringstream name;
  try {
    name << content_hash(bytes, file.extension().string()) << '-' << std::hexfloat << scale;
  } catch (const std::exception&) {
    return load_mesh(file, scale);  // no entry without its hash
  }
  std::string entry_name = name.str();
  for (char& c : entry_name) {
    if (c == '+' || c == '.') c = '_';
  }
  const auto entry = folder_ / (entry_name + ".mesh");
  std::error_code ignored;
  try {
    if (auto cached = read_entry(entry)) return cached;
  } catch (const std::exception&) {
    // unreadable: loaded and written anew below
  }
  auto mesh = load_mesh(file, scale);
  try {
    write_entry(entry, *mesh);
  } catch (const std::exception&) {
    std::filesystem::remove(entry, ignored);  // a cache that cannot be written is no cache
  }
  return mesh;
}

}  // namespace sim
