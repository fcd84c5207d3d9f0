// A solid's nodes, and a face-contact cloth's, held on the colliders inside implicit Euler's solve (private to
// the core library).
//
// A solid's nodes that the step would carry into a collider meet it inside the solve, so that the whole
// solid decelerates in the step where it lands and rests on the surface without sinking into it step after
// step: the contact stage after the step (contact_stage.h) stops only the nodes that reached the surface, so
// a solid landing fast (a cube dropped from 5 m, its bottom layer stopped within a step where the layer
// above moves more than its thickness) would turn its bottom tetrahedra inside out, and a resting one would
// fall freely in every solve and be pushed back only at its bottom nodes (measured: an 8 cm box sagging
// 1.8 mm at 4 ms steps, whatever its stiffness).
// The same holds keep a cloth with face contacts (the nodes of its contact triangles) on a collider: with
// the contact stage alone after the solve, a cloth that the step carried onto a ball, its faces unable to
// slip off, was stretched over it again in every step (measured: a 21 x 21 cloth of 5 cm dropped on a 15 cm
// ball at one sub-step of 1/60 s, its links 18 times their length within a second); held, it rests on it,
// its links 8 % long. Its faces and edges meet the colliders in the contact stage.
// A free node of a tetrahedron or a contact triangle is held when its predicted position x + offset lies,
// at the step's end (the surface moved on by h v_s), inside a collider (ContactQuery) at a depth d > 0, or
// less than |g| h^2 outside it (d > -|g| h^2: resting on it) unless its hold pulled it at the end of the
// last step (it is leaving). Its normal n is the surface's nearest to where the node starts the step (when
// the same collider is nearest there), d measured along it: a node that x + offset carries past a thin
// rail's axis is pushed back the way it came, not out through the far side (measured: a cloth dropped on a
// 5 mm rail had its middle row's nodes pushed down through it at landing). It is held on the surface along the normal n by a spring of stiffness k with
// h^2 k = kContactStiffness times its diagonal block's mean eigenvalue b: the block gains h^2 k n n^T and
// rhs h k d n, so that the solve leaves about 1 / kContactStiffness of d. Coulomb friction acts in the same
// solve, as a damping of the velocity relative to the surface across n (frictionDamping), pressed by
// N, the larger of b d / h^2, the force that stops the node's approach (its momentum b d / h over the
// step), and the force its hold took in the last step (noteForces; a resting node's weight). The contact
// stage then removes what depth remains. Other bodies keep the contact stage alone.
#pragma once

#include <vector>

#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/integrators/integrator.h"

namespace soft_body_sim
{
class ColliderHolds
{
public:
  /// The nodes of `model`'s solids and contact triangles, no force known on any.
  void analyze(const Model& model);
  /// Writes or reads the holds and their forces (state_archive.h); read after analyze.
  void carry(StateArchive& archive) { archive(hold_force_, holds_); }
  /// Finds the holds against `contacts` at the step's first Newton iteration and keeps them through the
  /// others; adds their blocks to the system's diagonal (after every element's: b is the node's block) and
  /// their push and friction to its rhs.
  void assemble(const NewtonPoint& point, const ContactQuery& contacts, bool first_iteration, BlockSystem& system);
  /// Drops the holds that pulled in the Newton iteration that solved `dv`, for the step's later iterations:
  /// the ballistic prediction that found them holds every node that would cross the surface in the step,
  /// also those that the solid's own elasticity stops above it (a landing's second layer of nodes; held, it
  /// would be pressed onto the first, its tetrahedra flat).
  void letGoPulling(double h, const NodeArray& dv);
  /// The force each hold of the last Newton iteration took, k (d - h n . dv) at its node's new depth: where
  /// it pulled (< 0) the node is held in the next step only if it is carried into the surface, where it
  /// pushed it is the normal force of the node's friction in the next step (a node resting on the surface,
  /// whose predicted depth is about 0, presses on it with its share of the weight). Every other solid node
  /// may be held again, with no force known. Each hold's collider receives the opposite of the impulse
  /// its rows gave the node, friction's included (ContactQuery::receive).
  void noteForces(const Model& model, double h, const NodeArray& dv, ContactQuery& contacts);

private:
  struct Hold
  {
    int node;
    NodeContact contact;  ///< as found at the step's first Newton iteration
    Vec3 found_at;        ///< [m] the node's predicted position then
    double found_depth;   ///< [m] its depth then, at the step's end (the surface moved on by h v_s)
    double depth;         ///< d [m] at the step's end, the node at this iteration's predicted position
    double scaled;        ///< h^2 k [kg] in this iteration
    double damping;       ///< c [kg/s] of its friction in this iteration (frictionDamping)
    Vec3 slip;            ///< v_t [m/s] that friction damped in this iteration

    void carry(StateArchive& archive)
    {
      archive(node, contact, found_at, found_depth, depth, scaled, damping, slip);
    }
  };
  void find(const NewtonPoint& point, const ContactQuery& contacts);
  /// k (d - h n . dv) [N]: the force `hold` took in the Newton iteration that solved dv (> 0 pushing).
  static double force(const Hold& hold, double h, const NodeArray& dv);

  std::vector<char> held_node_;  ///< per node: a node of a tetrahedron or a contact triangle
  /// per node: [N] the force its hold took in the last step (> 0 pushing, < 0 pulling: let go for a step),
  /// 0 without a hold
  std::vector<double> hold_force_;
  std::vector<Hold> holds_;  ///< the holds of the last Newton iteration
};

}  // namespace soft_body_sim
