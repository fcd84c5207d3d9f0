// Other bodies' nodes held on a soft solid's surface inside implicit Euler's solve (private to the core
// library).
//
// As a solid's node is held on a collider (collider_holds.h), a node p of another body (a rope's, a
// cloth's, another solid's) whose predicted position lies within its contact radius of a solid's boundary
// triangle, or behind it (SurfaceContacts::find), or, if its hold pushed in the last step, within
// max(|g| h^2, r_p / 2) of that, is held by a one-sided spring on the gap g = n . (x_p - q) - r_p,
// q = sum_k w_k x_k the triangle's nearest point at weights w; and so is an edge of one solid near or across
// an edge of another's, on the gap between their nearest points (SurfaceTouch). The Jacobian of g is
// weights_l n^T on the four nodes, so the two sides push each other apart with equal and opposite forces
// (momentum kept) and A gains h^2 k weights_l weights_m n n^T. k is kContactStiffness times the contact's
// effective mass b = 1 / sum_l weights_l^2 / b_l (b_l the free nodes' diagonal means): the solve leaves
// about 1 / kContactStiffness of the depth. Coulomb friction damps their relative velocity across n as on a
// collider, pressed by max(b d / h^2, the hold's force in the last step), the solid's `friction` (two
// solids': the mean). A hold couples a node to a triangle of another body, or two edges of two solids:
// those node pairs join the pattern when they first appear (placePairs).
//
// A solid's surface samples (Model::surface_samples) are held on the colliders in the same rows, the collider in p's
// place (no node, weight 0): a point q of a boundary triangle at fixed weights that is in a shape at x + h v is pushed
// out along the shape's normal, with friction relative to the shape's velocity at q, and the shape takes the opposite
// impulse (its wrench). So a rod thinner than the tetrahedra presses the surface in between the nodes instead of
// slicing into it. The normal and nearest point come from where q starts the sub-step (the side it is pushed to is the
// side it came from), its depth from where it ends; it is held while it is in (or within |g| h^2 if it pushed in the
// last step), and not near a corner whose node the collider holds itself (kNearCorner); its stiffness is
// kStiffestSampleStep's. The triangle's three nodes share a tetrahedron: no new pattern pairs.
//
// A face-contact cloth's or jelly's triangles are held on the colliders the same way, at the points a
// shape's edges, corners and thin parts touch them (ContactQuery::touchingFaces: the contact stage's
// faceTouch, from the triangle and the shape where they start the step to where x + h v and the shape's
// velocity take them; the corners are their nodes' collider holds). A point is held while it is in, or,
// if it pushed in the last step, within |g| h^2 of that. The prediction x + h v does not know the solve's
// own forces: after the step's Newton iterations, the faces that their velocities carry into a shape by
// more than the triangle's thickness, and that no hold holds yet, are held and the solve repeated
// (findMissedFaces, at most ImplicitEuler's kMissedFacePasses more iterations). So a 1 cm finger carries
// a taut cloth between two node columns at one sub-step of 1/60 s (its wing swung round the still finger
// by its tension, 5 cm in a step, crossed it without the repeat).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/contact/surface_contacts.h"
#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/integrators/integrator.h"

namespace soft_body_sim
{
class SurfaceHolds
{
public:
  /// Prepares for `model` if it has a solid with a surface and something that could touch it (else
  /// present() is false and every step has no holds). Call after every element kind has placed its pairs in
  /// `system`: the holds' pairs come after them.
  void analyze(const Model& model, const BlockSystem& system);
  /// Writes or reads what a step leaves for the next (state_archive.h): the holds and their forces, the
  /// pattern's slots; read after analyze, which makes the rest from the model.
  void carry(StateArchive& archive)
  {
    archive(touches_, holds_, hold_force_, edge_force_, element_pairs_, slot_of_pair_, slots_, sample_force_,
            faces_found_, held_faces_, face_force_);
  }
  /// Whether the model can have surface holds at all.
  bool present() const { return contacts_.has_value() || !sample_force_.empty() || faces_; }
  /// Whether the Newton iteration being assembled has any.
  bool empty() const { return holds_.empty(); }

  /// Finds the holds at the step's first Newton iteration and keeps them through the others (the surface
  /// samples' only with `colliders`); adds their push and friction to rhs (their blocks stay here:
  /// multiply, addToPreconditioner, write).
  void assemble(const NewtonPoint& point, bool first_iteration, BlockSystem& system, const ContactQuery* colliders);
  /// Gives every node pair of every hold (the node with the triangle's three, and those among themselves) a
  /// slot of the pattern. A pair not yet in it has the sparse pattern analysed again with it, the pairs of
  /// earlier holds kept unless they are more than kKeptPairs times the present holds' (then only these):
  /// resting contact keeps its pattern from step to step, sliding contact pays an analysis when it reaches a
  /// new triangle, and pairs of contacts long gone do not pile up.
  void placePairs(BlockSystem& system);

  void multiply(const Model& model, const NodeArray& p, NodeArray& out) const;
  void addToPreconditioner(const Model& model, std::vector<Eigen::Matrix3d>& diagonal) const;
  template <class Solver>
  void write(const Model&, Solver& solver) const
  {
    // A hold's blocks weights_l weights_m B (only ever in the sparse pattern: the block-tridiagonal solve
    // serves only steps without holds).
    for (std::size_t k = 0; k < holds_.size(); ++k)
    {
      const Hold& c = holds_[k];
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          solver.addDiagonal(c.nodes[l], (c.touch.weights[l] * c.touch.weights[l]) * c.block);
      for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
        if (slots_[kFourNodePairs.size() * k + p] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(slots_[kFourNodePairs.size() * k + p]),
                                (c.touch.weights[kFourNodePairs[p].first] * c.touch.weights[kFourNodePairs[p].second]) *
                                    c.block);
    }
  }

  /// After a Newton iteration that solved velocities v from positions x: holds the contact triangles' points
  /// that x + h v carries into a collider's edge, corner or thin part and that no hold has yet; true if there
  /// are any (then the solve should be repeated with them). The prediction x + h v_n that found the step's
  /// holds knows nothing of the solve's own forces: a taut cloth's wing that its tension swings round a finger
  /// within a step (measured: 5 cm at 1/60 s) would sweep through it.
  bool findMissedFaces(const Model& model, const NodeArray& x, const NodeArray& v, double h,
                       const ContactQuery& colliders);
  /// As ColliderHolds::letGoPulling.
  void letGoPulling(double h, const NodeArray& dv);
  /// As ColliderHolds::noteForces; the surface samples' impulses go to `colliders`.
  void noteForces(double h, const NodeArray& dv, ContactQuery* colliders);

private:
  struct Hold
  {
    SurfaceTouch touch;  ///< as found at the step's first Newton iteration (its nodes, weights, n)
    int nodes[4];        ///< touch.nodes, each -1 where pinned (or, for a sample, the collider's place)
    double depth;        ///< d [m] at this iteration's predicted positions
    double scaled;       ///< h^2 k [kg] in this iteration
    Eigen::Matrix3d block;  ///< B = h^2 k n n^T + h c (I - n n^T); A gains weights_l weights_m B on (l, m)
    /// Model::surface_samples' index of a sample held on a collider (then the collider is p: no node, weight
    /// 0); -1: a node p on a solid's surface
    int sample = -1;
    /// faces_found_'s index of a contact triangle's point held on a collider (as a sample); -1: none
    int face = -1;
    /// the collider a sample or a face touches (its normal points out of the collider)
    NodeContact contact{ Vec3::Zero(), Vec3::Zero() };
    double damping = 0.0;   ///< c [kg/s] of its friction in this iteration
    Vec3 slip = Vec3::Zero();  ///< the relative velocity across n that friction damped, before the solve

    /// A triangle's point held on a collider (a sample or a face): the collider in p's place.
    bool onCollider() const { return sample >= 0 || face >= 0; }
    void carry(StateArchive& archive)
    {
      archive(touch, nodes, depth, scaled, block, sample, face, contact, damping, slip);
    }
  };
  /// A face contact's name from step to step: its triangle, collider and the collider's feature.
  using FaceKey = std::tuple<std::size_t, int, std::size_t>;
  void find(const NewtonPoint& point, const ContactQuery* colliders);
  /// Holds every surface sample that is in a collider at x + h v (a triangle's points only where a collider
  /// comes within the triangle's reach).
  void findSamples(const NewtonPoint& point, const ContactQuery& colliders);
  /// Holds every contact triangle's point that a collider's edge, corner or thin part is in at x + h v
  /// (ContactQuery::touchingFaces; a node's own contact is ColliderHolds'), as a sample is held.
  void findFaces(const NewtonPoint& point, const ContactQuery& colliders);
  /// Holds faces_found_[k] (findFaces) as a sample is held: the collider in p's place.
  void holdFace(const Model& model, std::size_t k);
  /// [N] the force the hold of a node or of two edges took in the last step (> 0 pushing), 0 if it had none.
  double lastForce(const SurfaceTouch& touch) const;
  /// [N] the force a face contact's hold took in the last step (> 0 pushing), 0 if it had none.
  double lastForce(const FaceContact& face) const;
  /// k (d - h n . sum_l weights_l dv_l) [N]: the force `hold` took in the Newton iteration that solved dv
  /// (> 0 pushing).
  static double force(const Hold& hold, double h, const NodeArray& dv);

  /// A sample this near a corner (its weight of that node at least this) is not held while the corner's
  /// node is on the same collider.
  static constexpr double kNearCorner = 0.7;
  /// Two contact normals whose dot product exceeds this are the same (a flat shape under a triangle).
  static constexpr double kSameNormal = 1.0 - 1e-9;
  /// [s] A sample's hold has h^2 k = kContactStiffness b, b from the nodes' lumped masses (not from their
  /// diagonal blocks, which count the collider holds already on them: next to a node on the shape, that
  /// made a sample hundreds of times stiffer than the node's own hold, which threw a box off its rods), at
  /// sub-steps h of this and longer; at shorter ones k stays at this one's. Holds stiffer than that on a
  /// thin rod pressed into a soft box at 16 sub-steps of 1/60 s set its surface chattering at 10 m/s and let
  /// the rod into the box; at 1/240 s and longer they leave it in by at most 0.3 mm (test_face_contacts).
  static constexpr double kStiffestSampleStep = 1.0 / 240.0;
  /// How many times the present holds' node pairs the pattern keeps of earlier holds' (placePairs).
  static constexpr std::size_t kKeptPairs = 4;

  std::optional<SurfaceContacts> contacts_;  ///< the solids' surfaces, if anything can touch them
  std::vector<SurfaceTouch> touches_;        ///< what it found at a step's first iteration
  std::vector<Hold> holds_;                  ///< the holds of the last Newton iteration
  /// per node: [N] the force its hold took in the last step (> 0 pushing, < 0 pulling), 0 without a hold
  std::vector<double> hold_force_;
  /// the same for two edges' holds that had one in the last step: (SurfaceTouch::edges, [N]), by edges
  std::vector<std::pair<std::int64_t, double>> edge_force_;
  NodeArray predicted_;                      ///< x + h v where holds are found [m]
  std::size_t element_pairs_ = 0;            ///< how many of the pattern's pairs are the elements'
  std::unordered_map<std::uint64_t, std::size_t> slot_of_pair_;  ///< a hold's node pair -> its slot
  std::vector<int> slots_;                   ///< per hold, six: each node pair's slot, or -1
  /// per sampled triangle, its first sample in Model::surface_samples (and one past the last)
  std::vector<std::size_t> triangle_first_;
  std::vector<double> sample_force_;         ///< per surface sample: [N] as hold_force_; empty: no samples
  bool faces_ = false;                       ///< the model has contact triangles (face contacts)
  std::vector<FaceContact> faces_found_;     ///< the face contacts found in a step (its holds' `face`)
  std::vector<FaceContact> faces_more_;      ///< findMissedFaces' contacts
  std::vector<FaceKey> held_faces_;          ///< findMissedFaces': the held faces' keys, sorted
  std::vector<std::pair<FaceKey, double>> face_force_;  ///< the faces' holds' [N] in the last step, by key
};

}  // namespace soft_body_sim
