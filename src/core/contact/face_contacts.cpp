#include "core/contact/face_contacts.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <utility>

#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
std::vector<ShapeFeature> shapeFeatures(const Mesh& mesh)
{
  std::vector<ShapeFeature> features;
  if (!mesh.triangles)
    return features;
  const TriangleMesh& m = *mesh.triangles;
  // Each edge, by its two vertices (the smaller first), with the triangles that share it.
  std::unordered_map<std::uint64_t, std::vector<int>> sharing;
  const auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      sharing[key(m.triangles[t][k], m.triangles[t][(k + 1) % 3])].push_back(static_cast<int>(t));
  // A bend below this sine of the angle between the two faces' planes is flat (1e-9 rad: a mesh's
  // round-off, not a shape).
  constexpr double kFlat = 1e-9;
  for (const auto& [edge, triangles] : sharing)
  {
    const int a = static_cast<int>(edge >> 32), b = static_cast<int>(edge & 0xffffffffu);
    const Vec3 va = m.vertices[static_cast<std::size_t>(a)], vb = m.vertices[static_cast<std::size_t>(b)];
    bool outward = triangles.size() != 2;  // a rim, or more than two faces on an edge: kept
    if (!outward)
    {
      // The first triangle's outward normal, and the second's corner off the edge: below the first's plane
      // where the surface turns outward.
      const auto vertex = [&](int v) { return m.vertices[static_cast<std::size_t>(v)]; };
      const Eigen::Vector3i& first = m.triangles[static_cast<std::size_t>(triangles[0])];
      const Eigen::Vector3i& second = m.triangles[static_cast<std::size_t>(triangles[1])];
      const Vec3 normal = (vertex(first[1]) - vertex(first[0])).cross(vertex(first[2]) - vertex(first[0]));
      int off = second[0];
      for (int k = 0; k < 3; ++k)
        if (second[k] != a && second[k] != b)
          off = second[k];
      const Vec3 out = vertex(off) - va;
      outward = normal.dot(out) < -kFlat * normal.norm() * out.norm();
    }
    if (outward)
      features.push_back({ va, vb, 0.0, false });
  }
  // In a fixed order (the map's is not): by the edges' first and then second ends.
  std::sort(features.begin(), features.end(), [](const ShapeFeature& p, const ShapeFeature& q) {
    return std::lexicographical_compare(p.a.data(), p.a.data() + 3, q.a.data(), q.a.data() + 3) ||
           (p.a == q.a && std::lexicographical_compare(p.b.data(), p.b.data() + 3, q.b.data(), q.b.data() + 3));
  });
  return features;
}

}  // namespace soft_body_sim
