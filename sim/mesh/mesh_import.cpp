#include "sim/mesh/mesh_import.hpp"

#include <dlfcn.h>

#include <mutex>
#include <string>
#include <system_error>

namespace sim {
namespace {

using ImportFunction = bool (*)(const char*, TriangleMesh&, std::string&) noexcept;

constexpr const char* kModule = "libsim_mesh_import.so";

// The module beside the running executable, else where this build put it.
ImportFunction open_module(std::string& why) {
  std::error_code unknown;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", unknown);
  std::string tried;
  for (const std::filesystem::path& candidate :
       {unknown ? std::filesystem::path() : exe.parent_path() / kModule, std::filesystem::path(SIM_MESH_IMPORT_MODULE)}) {
    if (candidate.empty()) continue;
    void* module = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);  // kept open for the process's life
    if (!module) {
      const char* error = dlerror();
      tried += (tried.empty() ? "" : "; ") + std::string(error ? error : candidate.string());
      continue;
    }
    if (auto* f = reinterpret_cast<ImportFunction>(dlsym(module, "sim_mesh_import"))) return f;
    tried += (tried.empty() ? "" : "; ") + candidate.string() + " has no sim_mesh_import";
  }
  why = "the mesh importer " + std::string(kModule) + " cannot be opened (" + tried + ")";
  return nullptr;
}

}  // namespace

void import_mesh(const std::filesystem::path& file, TriangleMesh& mesh) {
  static std::once_flag once;
  static ImportFunction import = nullptr;
  static std::string why;
  std::call_once(once, [] { import = open_module(why); });
  if (!import) throw MeshError("cannot read mesh " + file.string() + ": " + why);
  std::string error;
  if (!import(file.c_str(), mesh, error)) throw MeshError("cannot read mesh " + file.string() + ": " + error);
}

}  // namespace sim
