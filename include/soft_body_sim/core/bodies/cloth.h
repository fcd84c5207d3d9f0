// Cloth (tum-mass-spring-tutorial.txt: "model it as a grid of mass points" joined by springs): a grid
// of equal-mass nodes with structural springs to the four direct neighbours, shear springs across each
// square's diagonals and, if asked, bending springs to the second neighbours along rows and columns.
// Also the grid layout the jelly shares: three named corners and row-by-row node numbering.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// Stiffness and dashpot of one family of springs of a generated body.
struct SpringParameters
{
  double stiffness = 0.0;  ///< k [N/m]
  double damping = 0.0;    ///< c [N s/m]
};

/// A parallelogram in space given by three corners [m]; the fourth, bottom_right, is
/// top_right + bottom_left - top_left. A grid of `columns` x `rows` nodes spans it: node (i, j), column
/// i = 0..columns-1 from the left edge and row j = 0..rows-1 from the top edge, has index j * columns + i
/// and sits at top_left + i / (columns - 1) (top_right - top_left) + j / (rows - 1) (bottom_left - top_left).
/// "Top" is only a name: a grid can lie in any orientation.
struct GridCorners
{
  Vec3 top_left = Vec3(0.0, 0.0, 1.0);
  Vec3 top_right = Vec3(1.0, 0.0, 1.0);
  Vec3 bottom_left = Vec3(0.0, 0.0, 0.0);

  /// The point at fractions s along the top edge and t along the left edge.
  Vec3 at(double s, double t) const { return top_left + s * (top_right - top_left) + t * (bottom_left - top_left); }
  /// (top_right - top_left) x (bottom_left - top_left): the grid's normal times its area [m^2].
  Vec3 areaNormal() const { return (top_right - top_left).cross(bottom_left - top_left); }
  /// False when the corners are (nearly) collinear or coincide and span no parallelogram.
  bool spansParallelogram() const;
};

/// The names of a grid's corners: top_left, top_right, bottom_left, bottom_right.
const std::vector<std::string>& gridCornerNames();
/// The index of the named corner node of a grid of columns x rows nodes; nullopt for an unknown name.
std::optional<int> gridCornerNode(const std::string& name, int columns, int rows);

struct ClothDef
{
  int nx = 10;                                           ///< nodes per row (along the top edge), >= 2
  int ny = 10;                                           ///< nodes per column (along the left edge), >= 2
  GridCorners corners;                                   ///< where the cloth starts, flat and at rest [m]
  double mass = 0.2;                                     ///< total mass [kg], spread equally over the nodes
  SpringParameters structural{ 200.0, 0.05 };            ///< springs to the 4 direct neighbours
  SpringParameters shear{ 50.0, 0.05 };                  ///< springs across each square's 2 diagonals
  std::optional<SpringParameters> bending;               ///< springs to second neighbours; none by default
  std::vector<int> pinned;                               ///< pinned node indices; negative counts from the end
  double thickness = 0.0;                                ///< [m] >= 0: contact radius of its nodes
  /// Its nodes keep apart by their thickness from each other and from other self-colliding bodies
  /// (self_contacts.h): a folded cloth's layers stay apart. Needs 0.36 <= thickness / spacing < 0.5 (the
  /// spacing between neighbouring nodes): thinner, a node slips between four others; thicker, neighbours
  /// overlap at rest. With face_contacts its triangles' edges and faces collide instead of its nodes as
  /// balls, and any thickness below 0.5 spacing will do.
  bool self_collision = false;
  double self_friction = 0.0;  ///< Coulomb coefficient [-] between touching nodes, >= 0
  /// Its triangles (two per square) meet spheres, capsules, boxes, cylinders and meshes over their faces
  /// and edges, not only at its nodes (face_contacts.h): a finger or rail thinner than the node spacing does
  /// not pass between them. With self_collision they are also what other self-colliding bodies and the
  /// cloth itself meet (self_contacts.h). Off by default, experimental: under xpbd at one sub-step of
  /// 1/60 s a 5 cm cloth dropped onto a ball of 15 cm radius is torn (at four it rests).
  bool face_contacts = false;
};

/// Appends to `body` a grid of columns x rows nodes of equal mass (mass / (columns rows) [kg]) spanning
/// `corners`, node (i, j) = j columns + i at corners.at(i / (columns - 1), j / (rows - 1)), then springs at
/// rest between direct neighbours along rows and columns (`edges`), then across both diagonals of each
/// square (`diagonals`). The cloth's and the jelly's common grid; columns and rows >= 2.
/// The checks of a grid body (cloth, jelly) named `what`: corners that span a parallelogram and a total
/// mass > 0 (DefinitionError otherwise).
void requireGrid(const std::string& what, const GridCorners& corners, double mass);
/// The checks of a spring family `key` of a grid body: stiffness > 0, damping >= 0.
void requireSprings(const std::string& what, const std::string& key, const SpringParameters& springs);

void addSpringGrid(BodyDef& body, const GridCorners& corners, int columns, int rows, double mass,
                   const SpringParameters& edges, const SpringParameters& diagonals);
/// Sets the faces (Look) of a grid of columns x rows nodes that addSpringGrid laid as `body`'s first nodes
/// (node (i, j) = j columns + i): two per square, split along the diagonal from (i, j) to (i + 1, j + 1),
/// row by row; with `face_contacts` they are its contact triangles too (face_contacts.h). The cloth's and
/// the jelly's.
void addGridTriangles(BodyDef& body, int columns, int rows, bool face_contacts);

/// The cloth as nodes and springs (type "cloth"), every spring at rest in the flat initial layout;
/// throws std::invalid_argument on a bad definition and std::out_of_range on a bad pinned index.
BodyDef buildCloth(const std::string& name, const ClothDef& cloth);

}  // namespace soft_body_sim
