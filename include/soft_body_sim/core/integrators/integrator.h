// Time integrators. Each advances a model by one (sub)step h: every one steps springs, dashpots, gas cells,
// gravity, drag and distance constraints, so that their results can be compared; rods and soft solids run
// only under implicit_euler (each element kind says which integrators run it: element_kinds.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
enum class IntegratorType
{
  ExplicitEuler,
  SemiImplicitEuler,
  Verlet,
  VelocityVerlet,
  Rk4,
  ImplicitEuler,
  Xpbd,
};

/// The scene-file name of each integrator, e.g. "semi_implicit_euler".
std::string integratorName(IntegratorType type);
/// Parses a scene-file name; false if the name is unknown.
bool integratorFromName(const std::string& name, IntegratorType& type);
/// Every valid name, in declaration order.
const std::vector<std::string>& integratorNames();

/// A node within its contact radius of a collider's surface, as a solve sees it (ContactQuery).
struct NodeContact
{
  Vec3 normal;            ///< the surface's outward unit normal
  Vec3 velocity;          ///< [m/s] of the surface point (0 for a fixed collider)
  double friction = 0.0;  ///< Coulomb coefficient [-]
  double depth = 0.0;     ///< [m] how far the node is inside its contact radius (< 0: that far outside it)
  int collider = -1;      ///< which collider it is, for ContactQuery::receive (-1: none)

  void carry(StateArchive& archive) { archive(normal, velocity, friction, depth, collider); }
};

/// A point of a contact triangle that a collider's edge, corner or thin part comes near between the
/// triangle's nodes (face contacts; ContactQuery::touchingFaces).
struct FaceContact
{
  std::size_t triangle = 0;  ///< its index in Model::contact_triangles
  Vec3 weight;               ///< the point sum_k weight_k x_k of the triangle's corners
  /// normal: the way the point leaves the shape; velocity: the shape's at the contact; depth [m]: how far
  /// the point is inside the triangle's thickness from the shape at the sub-step's end (< 0: outside)
  NodeContact contact;
  std::size_t feature = 0;  ///< which of the collider's features (with the triangle and the collider, the contact's name)

  void carry(StateArchive& archive) { archive(triangle, weight, contact, feature); }
};

/// The colliders as a solve can ask about them (the contact stage, contact_stage.h).
class ContactQuery
{
public:
  virtual ~ContactQuery() = default;
  /// The surface nearest to node `node` placed at `x` [m], if it is within the node's contact radius
  /// plus `margin` [m] of one; the deepest if several are.
  virtual bool touching(const Model& model, int node, const Vec3& x, double margin, NodeContact& contact) const = 0;
  /// A solve that took `contact` into itself gave its node a contact impulse: the collider receives the
  /// opposite, `impulse` [N s], at `point` [m] (World::colliderWrenches).
  virtual void receive(const NodeContact& contact, const Vec3& point, const Vec3& impulse) = 0;
  /// Where the contact triangles (Model::contact_triangles), moving from `start` to `end` [m] over a sub-step
  /// of h [s], meet a collider's edges, corners or thin parts between their nodes (face_contacts.h; their
  /// nodes are `touching`'s), each within `margin` [m] of touching at the sub-step's end, the colliders
  /// moved on by their velocities: into `found` (cleared first).
  virtual void touchingFaces(const Model& /*model*/, const NodeArray& /*start*/, const NodeArray& /*end*/,
                             double /*h*/, double /*margin*/, std::vector<FaceContact>& found) const
  {
    found.clear();
  }
};

/// The forces inside the bodies in the last sub-step, as an integrator's solve had them.
struct InternalForces
{
  Eigen::VectorXd tension;   ///< [N] per spring, then per distance constraint (model order), > 0 stretched
  Eigen::VectorXd pressure;  ///< [N/m] per pressure cell (PressureCell), > 0 pushing its outline out
};

class Integrator
{
public:
  virtual ~Integrator() = default;
  /// A copy carrying everything the next steps depend on (history, multipliers, warm data): stepped as the
  /// original is, it gives the same bits. Called between steps.
  virtual std::unique_ptr<Integrator> clone() const = 0;
  /// Makes this one a copy of `other` (as clone), reusing its buffers; false (and unchanged) if `other` is
  /// of another kind.
  virtual bool assign(const Integrator& other) = 0;
  /// Writes or reads what a clone carries (state_archive.h): what the next steps depend on, not the
  /// scratch a step makes anew.
  virtual void carry(StateArchive& archive, const Model& model) = 0;
  /// Advances `state` by h [s]. Pinned nodes (inverse mass 0) are never moved: their position and
  /// velocity belong to the caller. `iterations` is the constraint/relaxation/Newton count.
  virtual void step(const Model& model, State& state, double h, int iterations) = 0;
  /// step(), where the scene has colliders (`contacts`; null: none). A solve that can take contacts into
  /// it does (xpbd's chains: chain_contacts.h; implicit Euler's solids: collider_holds.h) and hands the
  /// impulses it gave back to `contacts` (ContactQuery::receive); the others leave them to the contact
  /// stage that follows.
  virtual void stepWithContacts(const Model& model, State& state, double h, int iterations,
                                ContactQuery* /*contacts*/)
  {
    step(model, state, h, iterations);
  }
  /// The forces inside the bodies in the last sub-step: each link's tension (it pulls each end toward the
  /// other with that force) and each cell's gas pressure. The force-based schemes take the spring and gas
  /// laws at `state` and, for constraints, their constraint pass's multipliers as forces -lambda / h^2;
  /// xpbd takes its multipliers for all three. Before the first step: the laws at `state`, and 0 for
  /// constraints.
  virtual void internalForces(const Model& model, const State& state, InternalForces& forces) const = 0;
  /// The state was changed from outside the integrator (an anchor or controller moved its nodes, a
  /// plane contact changed a velocity, a node was set): drop anything cached from the old state.
  virtual void invalidate() {}
  /// The model was changed (gravity, drag, stiffness, pressure, a node pinned or released): drop anything
  /// cached from the old model as well as from the old state.
  virtual void modelChanged() { invalidate(); }
};

std::unique_ptr<Integrator> makeIntegrator(IntegratorType type);

}  // namespace soft_body_sim
