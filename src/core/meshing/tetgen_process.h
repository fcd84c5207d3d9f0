// TetGen run as a separate program on a piecewise linear complex (private to the core library; why a
// program and not the library: volume_mesh.cpp).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "soft_body_sim/core/meshing/volume_mesh.h"

namespace soft_body_sim
{
/// A piecewise linear complex: TetGen's input, a closed surface of flat polygons [m].
struct Plc
{
  std::vector<Eigen::Vector3d> vertices;  ///< [m]
  std::vector<std::vector<int>> facets;   ///< each a planar polygon's vertex indices, in order
};

/// The indices of the facets of `plc` that cross another (`tetgen -d`), ascending; empty when none do.
/// Throws std::runtime_error when tetgen cannot be run or fails.
std::vector<int> intersectingFacets(const Plc& plc);

/// The quality mesh of the solid `plc` bounds (`tetgen -pq1.414a<max_volume>`): tetrahedra of volume
/// <= max_volume [m^3] and radius-edge ratio <= 1.414, in TetGen's orientation; no surface. Throws
/// std::runtime_error when tetgen cannot be run or fails.
TetMesh tetrahedralise(const Plc& plc, double max_volume);

}  // namespace soft_body_sim
