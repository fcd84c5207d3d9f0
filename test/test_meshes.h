// Closed triangle meshes built in code (a box, a latitude-longitude sphere, an L-shaped block), an STL
// writer, and brute-force geometry on them (Ericson's closest point on a triangle, the winding number):
// the truth the mesh collider tests and the bench measure the distance field against.
#pragma once

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim::test
{
/// A box of full extents `size` [m] centred on the origin: 8 corners, 12 triangles, outward winding.
inline TriangleMesh boxMesh(const Eigen::Vector3d& size)
{
  TriangleMesh mesh;
  for (int k = 0; k < 8; ++k)
    mesh.vertices.emplace_back((k & 1 ? 0.5 : -0.5) * size.x(), (k & 2 ? 0.5 : -0.5) * size.y(),
                               (k & 4 ? 0.5 : -0.5) * size.z());
  // Two triangles per face, each face's corners counter-clockwise seen from outside.
  const int faces[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
  for (const auto& f : faces)
  {
    mesh.triangles.emplace_back(f[0], f[1], f[2]);
    mesh.triangles.emplace_back(f[0], f[2], f[3]);
  }
  return mesh;
}

/// A sphere of `radius` [m] about the origin as `slices` meridians and `stacks` bands of latitude:
/// 2 slices (stacks - 1) triangles (100 x 51: 10,000).
inline TriangleMesh uvSphere(double radius, int slices, int stacks)
{
  TriangleMesh mesh;
  mesh.vertices.emplace_back(0, 0, radius);  // north pole, 0
  for (int i = 1; i < stacks; ++i)
    for (int j = 0; j < slices; ++j)
    {
      const double polar = M_PI * i / stacks, azimuth = 2.0 * M_PI * j / slices;
      mesh.vertices.emplace_back(radius * std::sin(polar) * std::cos(azimuth),
                                 radius * std::sin(polar) * std::sin(azimuth), radius * std::cos(polar));
    }
  const int south = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0, 0, -radius);
  const auto ring = [slices](int i, int j) { return 1 + (i - 1) * slices + (j % slices); };
  for (int j = 0; j < slices; ++j)
  {
    mesh.triangles.emplace_back(0, ring(1, j), ring(1, j + 1));
    mesh.triangles.emplace_back(south, ring(stacks - 1, j + 1), ring(stacks - 1, j));
    for (int i = 1; i + 1 < stacks; ++i)
    {
      mesh.triangles.emplace_back(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
      mesh.triangles.emplace_back(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
    }
  }
  return mesh;
}

/// A non-convex block: the L-shaped profile (x, z) = (0, 0), (0.3, 0), (0.3, 0.05), (0.05, 0.05),
/// (0.05, 0.2), (0, 0.2) [m] (a foot 0.3 m long and 5 cm thick, an upright 5 cm thick and 0.2 m tall)
/// extruded from y = 0 to 0.2 m: 12 corners, 20 triangles.
inline TriangleMesh lBlock()
{
  const double profile[6][2] = { { 0, 0 }, { 0.3, 0 }, { 0.3, 0.05 }, { 0.05, 0.05 }, { 0.05, 0.2 }, { 0, 0.2 } };
  TriangleMesh mesh;
  for (const double y : { 0.0, 0.2 })
    for (const auto& p : profile)
      mesh.vertices.emplace_back(p[0], y, p[1]);
  // The profile runs counter-clockwise seen from -y: the y = 0 cap's outward side. Its fans start from
  // the concave corner (3), so every triangle lies inside the L.
  const int cap[4][3] = { { 3, 4, 5 }, { 3, 5, 0 }, { 3, 0, 1 }, { 3, 1, 2 } };
  for (const auto& t : cap)
  {
    mesh.triangles.emplace_back(t[0], t[1], t[2]);
    mesh.triangles.emplace_back(6 + t[0], 6 + t[2], 6 + t[1]);
  }
  for (int k = 0; k < 6; ++k)
  {
    const int a = k, b = (k + 1) % 6;
    mesh.triangles.emplace_back(a, 6 + b, b);
    mesh.triangles.emplace_back(a, 6 + a, 6 + b);
  }
  return mesh;
}

/// Writes `mesh` as a binary STL file (80-byte header, triangle count, per triangle a normal, three
/// corners and a 2-byte attribute, little-endian floats).
inline void writeBinaryStl(const TriangleMesh& mesh, const std::string& path)
{
  std::ofstream out(path, std::ios::binary);
  const std::string header(80, ' ');
  out.write(header.data(), 80);
  const std::uint32_t count = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const Eigen::Vector3i& t : mesh.triangles)
  {
    const Eigen::Vector3d& a = mesh.vertices[t.x()];
    const Eigen::Vector3d& b = mesh.vertices[t.y()];
    const Eigen::Vector3d& c = mesh.vertices[t.z()];
    const Eigen::Vector3f n = (b - a).cross(c - a).normalized().cast<float>();
    out.write(reinterpret_cast<const char*>(n.data()), 12);
    for (const Eigen::Vector3d* v : { &a, &b, &c })
    {
      const Eigen::Vector3f f = v->cast<float>();
      out.write(reinterpret_cast<const char*>(f.data()), 12);
    }
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
}

/// The point of triangle abc nearest to p (Ericson, Real-Time Collision Detection, 5.1.5), and whether it
/// lies in the triangle's interior (not on an edge or a corner).
inline Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                         const Eigen::Vector3d& c, bool* interior = nullptr)
{
  if (interior)
    *interior = false;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0)
    return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3)
    return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6)
    return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  if (interior)
    *interior = true;
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

/// The winding number of a closed mesh about p: the sum of its triangles' signed solid angles (Van
/// Oosterom and Strackee's formula) over 4 pi; 1 inside, 0 outside, whatever the mesh's shape.
inline double windingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p)
{
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles)
  {
    const Eigen::Vector3d a = mesh.vertices[t.x()] - p, b = mesh.vertices[t.y()] - p, c = mesh.vertices[t.z()] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    total += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
  }
  return total / (4.0 * M_PI);
}

/// The brute-force signed distance from p to a closed mesh [m] (negative inside), over every triangle.
struct BruteForce
{
  double distance = 0.0;
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();
  int triangle = -1;
  bool interior = false;  ///< the closest point is inside its triangle, not on an edge or a corner
};

inline BruteForce bruteForce(const TriangleMesh& mesh, const Eigen::Vector3d& p)
{
  BruteForce best;
  double nearest = 1e300;
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
  {
    const Eigen::Vector3i& t = mesh.triangles[k];
    bool interior = false;
    const Eigen::Vector3d q = closestOnTriangle(p, mesh.vertices[t.x()], mesh.vertices[t.y()], mesh.vertices[t.z()], &interior);
    if ((p - q).norm() < nearest)
    {
      nearest = (p - q).norm();
      best.closest = q;
      best.triangle = static_cast<int>(k);
      best.interior = interior;
    }
  }
  best.distance = windingNumber(mesh, p) > 0.5 ? -nearest : nearest;
  return best;
}

}  // namespace soft_body_sim::test
