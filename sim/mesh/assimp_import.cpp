// The module that reads mesh files with Assimp (mesh_import.hpp): one entry point, C linkage,
// for dlsym.

#include <string>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "sim/mesh/triangle_mesh.hpp"

namespace {

void append_node(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, sim::TriangleMesh& out) {
  const aiMatrix4x4 transform = parent * node.mTransformation;
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
    if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    std::vector<std::uint32_t> piece;
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = transform * mesh.mVertices[v];
      out.vertices.emplace_back(p.x, p.y, p.z);
      out.bounds.extend(out.vertices.back());
      piece.push_back(base + v);
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      out.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
    out.pieces.push_back(std::move(piece));
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) append_node(scene, *node.mChildren[c], transform, out);
}

}  // namespace

// Fills `mesh` from the file; false with the reason in `error` when it cannot be read.
extern "C" bool sim_mesh_import(const char* file, sim::TriangleMesh& mesh, std::string& error) noexcept {
  try {
    Assimp::Importer importer;
    // A COLLADA file's <unit> is applied (it is the file's own statement of its unit); its
    // <up_axis> is not: a mesh is in its part's frame, whose coordinates the product's links
    // use as the CAD system wrote them.
    importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
    // Corners are welded by position alone: a vendor's STL gives each triangle its own normal,
    // and corners that differ by their normal were not joined (a bearing: 10 512 open edges).
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                            aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                            aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS);
    const aiScene* scene = importer.ReadFile(file, aiProcess_RemoveComponent | aiProcess_Triangulate |
                                                       aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
    if (!scene || !scene->mRootNode || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
      error = importer.GetErrorString();
      return false;
    }
    append_node(*scene, *scene->mRootNode, aiMatrix4x4(), mesh);
    return true;
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
}
