// Bending and twisting of rods (Model::rods, a scene's `type: rod`): the discrete elastic rod of Bergou,
// Wardetzky, Robinson, Audoly and Grinspun 2008 ("Discrete elastic rods", DER), for an isotropic rod
// (circular cross-section) straight and untwisted at rest, with its twist quasi-static (their section 7).
//
// Why this formulation: a cable's bending and twisting waves are far faster than anything a robot does
// with it, and its statics (the cantilever, the elastica, the torque of a twisted cable) are what users
// check it against. DER's state is the nodes' positions only: bending is a function of them, and for an
// isotropic rod the twist, which relaxes instantly along it, is spread evenly between the two held ends
// and enters as one number per rod (its total twist). So the rod joins the implicit_euler Newton system
// as three-node blocks beside the springs that stretch it, and the system's fixed point is the discrete
// rod's exact equilibrium whatever the step. Shear (a Cosserat rod's fifth mode) is left out: for a
// slender rod its deflection is (r / L)^2 E / G of the bending's (1e-4 for a 5 mm cable 1 m long).
// Segment orientations are not state but follow from the positions (rodFrames): the frame of the first
// segment transported along the rod without twisting (parallel transport), turned by its share of the
// twist.
#pragma once

#include <vector>

#include "soft_body_sim/core/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// The curvature binormal at a vertex between the edge e0 that enters it and the edge e1 that leaves it,
///   kb = 2 e0 x e1 / (l0 l1 + e0 . e1)      (l0 l1 = `rest_product` of their rest lengths; DER eq. 1),
/// |kb| = 2 tan(phi / 2) at rest lengths (phi the turning angle), and its derivatives, D = l0 l1 + e0 . e1:
///   dkb/de0 = -(2 [e1]x + kb e1^T) / D,    dkb/de1 = (2 [e0]x - kb e0^T) / D    ([a]x b = a x b).
struct CurvatureBinormal
{
  Vec3 kb;
  Eigen::Matrix3d d_e0;
  Eigen::Matrix3d d_e1;
};
CurvatureBinormal curvatureBinormal(const Vec3& e0, const Vec3& e1, double rest_product);

/// A vertex where a rod bends: the node `at` between the edge x_at - x_before and the edge x_after - x_at.
/// At a held end the missing edge is the held frame's x axis times l (a ghost edge: the clamp's
/// direction), and `before` or `after` is -1. Its energy is E = E I |kb|^2 / (2 D) = weight |kb|^2 with D
/// its share of the rod's length: l inside, l / 2 at a held end (the half segment between the clamp and
/// the first midpoint). Discretised this way the cantilever's tip deflection converges at second order.
struct RodVertex
{
  int before;     ///< global node, or -1: the held first node's ghost edge
  int at;         ///< global node
  int after;      ///< global node, or -1: the held last node's ghost edge
  double weight;  ///< E I / (2 D) [N m^3]
};

/// Appends the rod's bending vertices: its inner nodes, then its held ends.
void appendRodVertices(const Rod& rod, std::vector<RodVertex>& vertices);

/// The bending vertex at held end `end` (0: first node, 1: last), with its ghost edge.
RodVertex heldVertex(const Rod& rod, int end);

/// The two edges [m] of vertex `vertex` of `rod` at positions x (see RodVertex).
void vertexEdges(const Rod& rod, const RodVertex& vertex, const NodeArray& x, Vec3& e0, Vec3& e1);

/// Throws std::invalid_argument if `model` has a rod and `integrator` is not implicit_euler, the only
/// integrator that bends and twists rods (the others would run it as a chain of springs).
void requireRodIntegrator(const Model& model, IntegratorType integrator);

/// The index in model.rods of the rod whose held end is node `node`, with that end (0 first, 1 last) in
/// `end`; -1 if no rod holds an end there.
int heldRodEnd(const Model& model, int node, int& end);

/// The unit axis of a held end's frame now (end 0: first node, 1: last), pointing along the rod.
inline Vec3 heldAxis(const Rod& rod, int end) { return rod.end_frame[end] * Vec3::UnitX(); }

/// The rod's total twist [rad] at x: the angle, about the last held axis, from its first held frame's
/// y axis carried along the rod by parallel transport (through the first held axis, every segment and the
/// last held axis) to its last held frame's y axis; > 0 when the last end is turned right-handedly about
/// the rod. Of the values 2 pi apart, the one nearest `near` (the last step's: a rod counts whole turns).
/// 0 for a rod that does not twist (Rod::twists).
double rodTwist(const Rod& rod, const NodeArray& x, double near);

/// d(twist)/dx [rad/m] of each of the rod's nodes (3 x count; the twist's holonomy, DER section 6): with
/// kb_k the curvature binormal of unit tangents at each bend of the transport (held axes included),
/// each segment e_j contributes (kb_before + kb_after) / (2 |e_j|) to its last node and minus that to its
/// first. Zero on a straight rod: twisting alone does not move the nodes.
void rodTwistGradient(const Rod& rod, const NodeArray& x, NodeArray& gradient);

/// Bending plus twisting energy [J] of the rod at x with total twist `twist`:
///   sum over vertices of weight |kb|^2  +  G J twist^2 / (2 L)     (the twist term only if it twists).
double rodEnergy(const Rod& rod, const NodeArray& x, double twist);

/// Adds the rod's bending and twisting forces -dE/dx [N] at x with total twist `twist` to `force` (3 x
/// the model's nodes): -2 weight J_k^T kb at each vertex's nodes (J_k = dkb/dx_k), and
/// -(G J twist / L) d(twist)/dx.
void accumulateRodForces(const Rod& rod, const NodeArray& x, double twist, NodeArray& force);

/// Each segment's material frame at x with total twist `twist` (count - 1 of them): x along the segment;
/// the first held frame (or, at a free first end, the rest frame turned onto the first segment) carried
/// by parallel transport, and turned about the segment by twist times its midpoint's share of the length.
void rodFrames(const Rod& rod, const NodeArray& x, double twist, std::vector<Eigen::Quaterniond>& frames);

/// The torque [N m] the rod exerts on held end `end` (0: first node, 1: last) at x with total twist
/// `twist`: its bending moment at the clamp, l (g x a) with g = dE/d(ghost edge) and a the held axis, and
/// its twisting moment -+ G J twist / L about that axis. The twist's dependence on the held axis's
/// direction (its holonomy through the clamp) is not included.
Vec3 heldEndTorque(const Rod& rod, const NodeArray& x, double twist, int end);

}  // namespace soft_body_sim
