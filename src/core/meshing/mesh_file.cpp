// Reading a mesh collider's triangles with assimp (mesh_field.h).
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>

#include "soft_body_sim/core/definition_error.h"
#include "soft_body_sim/core/input_file.h"
#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
Eigen::Vector3d TriangleMesh::lower() const
{
  Eigen::Vector3d low = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < vertices.size(); ++k)
    low = k == 0 ? vertices[k] : Eigen::Vector3d(low.cwiseMin(vertices[k]));
  return low;
}

Eigen::Vector3d TriangleMesh::upper() const
{
  Eigen::Vector3d high = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < vertices.size(); ++k)
    high = k == 0 ? vertices[k] : Eigen::Vector3d(high.cwiseMax(vertices[k]));
  return high;
}

double TriangleMesh::boundingRadius() const
{
  double radius = 0.0;
  for (const Eigen::Vector3d& v : vertices)
    radius = std::max(radius, v.norm());
  return radius;
}

TriangleMesh readTriangleMesh(const std::string& path, const Eigen::Vector3d& scale)
{
  const std::string what = "mesh file '" + path + "'";
  // Before assimp opens it: its open of a FIFO blocks until a writer comes, and it reads any file whole.
  const std::string unreadable = unreadableFileReason(path, kMaxMeshFileBytes, "kMaxMeshFileBytes");
  requireDefinition(unreadable.empty(), what, { "mesh" }, "cannot be read: " + unreadable);
  Assimp::Importer importer;
  // Only positions matter: without normals and texture coordinates, JoinIdenticalVertices merges the
  // corners that faces share (an STL repeats them per face), so the mesh is one connected surface.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                          aiComponent_MATERIALS);
  // Points and lines are no surface: dropped.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_SortByPType |
                                  aiProcess_PreTransformVertices | aiProcess_JoinIdenticalVertices);
  requireDefinition(scene != nullptr, what, { "mesh" }, std::string("cannot be read: ") + importer.GetErrorString());
  TriangleMesh mesh;
  for (unsigned int m = 0; m < scene->mNumMeshes; ++m)
  {
    const aiMesh& part = *scene->mMeshes[m];
    const int offset = static_cast<int>(mesh.vertices.size());
    for (unsigned int v = 0; v < part.mNumVertices; ++v)
      mesh.vertices.push_back(
          Eigen::Vector3d(part.mVertices[v].x, part.mVertices[v].y, part.mVertices[v].z).cwiseProduct(scale));
    for (unsigned int f = 0; f < part.mNumFaces; ++f)
      if (part.mFaces[f].mNumIndices == 3)
      {
        const unsigned int* i = part.mFaces[f].mIndices;
        mesh.triangles.emplace_back(offset + static_cast<int>(i[0]), offset + static_cast<int>(i[1]),
                                    offset + static_cast<int>(i[2]));
      }
  }
  requireDefinition(!mesh.triangles.empty(), what, { "mesh" }, "holds no triangle");
  return mesh;
}

}  // namespace soft_body_sim
