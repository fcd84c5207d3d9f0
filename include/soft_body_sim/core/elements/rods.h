// Bending and twisting of rods (Model::rods, a scene's `type: rod`): the discrete elastic rod of Bergou,
// Wardetzky, Robinson, Audoly and Grinspun 2008 ("Discrete elastic rods", DER), for an isotropic rod
// (circular cross-section) straight and untwisted at rest, with its twist quasi-static (their section 7).
//
// Why this formulation: a cable's bending and twisting waves are far faster than anything a robot does
// with it, and its statics (the cantilever, the elastica, the torque of a twisted cable) are what users
// check it against. DER's state is the nodes' positions only: bending is a function of them, and for an
// isotropic rod the twist, which relaxes instantly along it, is spread evenly between two consecutive
// stations (the places where it is held: clamped or anchored ends, grasps) and enters as one number per
// interval between them (its total twist there). So the rod joins the implicit_euler Newton system
// as three-node blocks beside the springs that stretch it, and the system's fixed point is the discrete
// rod's exact equilibrium whatever the step. Shear (a Cosserat rod's fifth mode) is left out: for a
// slender rod its deflection is (r / L)^2 E / G of the bending's (1e-4 for a 5 mm cable 1 m long).
// Segment orientations are not state but follow from the positions (rodFrames): a station's frame
// transported along the rod without twisting (parallel transport), turned by its share of the twist.
#pragma once

#include <vector>

#include "soft_body_sim/core/integrators/integrator.h"
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
/// At a station of one node (a held end, a grasp) the rod is held in the direction of the station's frame's
/// x axis on each side: the missing edge is that axis times l (a ghost edge: the clamp's direction), and
/// `before` or `after` is -1. Its energy is E = E I |kb|^2 / (2 D) = weight |kb|^2 with D its share of
/// the rod's length: l inside, l / 2 beside a station (the half segment between the clamp and the first
/// midpoint). Discretised this way the cantilever's tip deflection converges at second order.
struct RodVertex
{
  int before;     ///< global node, or -1: the ghost edge of station `station`
  int at;         ///< global node
  int after;      ///< global node, or -1: the ghost edge of station `station`
  int station;    ///< index into Rod::stations of the ghost edge's station, or -1
  double weight;  ///< E I / (2 D) [N m^3]
};

/// Appends the rod's bending vertices: its inner nodes apart from its stations of one node, then those
/// stations' two half vertices (one at an end).
void appendRodVertices(const Rod& rod, std::vector<RodVertex>& vertices);

/// The two edges [m] of vertex `vertex` of `rod` at positions x (see RodVertex).
void vertexEdges(const Rod& rod, const RodVertex& vertex, const NodeArray& x, Vec3& e0, Vec3& e1);


/// A rod station in a model: rod index into Model::rods and station index into its stations (-1: none).
struct StationIndex
{
  int rod = -1;
  int station = -1;
  explicit operator bool() const { return rod >= 0; }
};

/// The station of a rod in `model` that holds node `node`, if any.
StationIndex findRodStation(const Model& model, int node);
inline RodStation& rodStation(Model& model, StationIndex at)
{
  return model.rods[static_cast<std::size_t>(at.rod)].stations[static_cast<std::size_t>(at.station)];
}
inline const RodStation& rodStation(const Model& model, StationIndex at)
{
  return model.rods[static_cast<std::size_t>(at.rod)].stations[static_cast<std::size_t>(at.station)];
}

/// The held axis (unit, along the rod) of station `s` where the rod enters it (side 0) or leaves it (1).
inline Vec3 stationAxis(const Rod& rod, int s, int side) { return rod.stations[static_cast<std::size_t>(s)].frame[side] * Vec3::UnitX(); }

/// The twist interval after station s (to station s + 1): its length [m] between the two stations' nearest
/// nodes (segment_length per segment between them), and its slot in State::twist (station s's last node).
double intervalLength(const Rod& rod, int s);
inline int twistSlot(const Rod& rod, int s) { return rod.stations[static_cast<std::size_t>(s)].last; }

/// The twist [rad] between stations s and s + 1 at x: the angle, about station s + 1's entering axis, from
/// station s's leaving frame's y axis carried to it by parallel transport (through station s's leaving
/// axis, every segment between them and station s + 1's entering axis) to station s + 1's entering frame's
/// y axis; > 0 when the later station is turned right-handedly about the rod. Of the values 2 pi apart,
/// the one nearest `near` (the last step's: a rod counts whole turns).
double intervalTwist(const Rod& rod, int s, const NodeArray& x, double near);

/// State::twist's entries of the rod updated to x (each interval's, counted on from its last value).
void updateRodTwists(const Rod& rod, const NodeArray& x, Eigen::VectorXd& twist);

/// d(twist)/dx of the interval after station s, of each of the rod's nodes (3 x count, zero outside the
/// interval; the twist's holonomy, DER section 6): with kb_k the curvature binormal of unit tangents at
/// each bend of the transport (the held axes included), each segment e_j between the stations contributes
/// (kb_before + kb_after) / (2 |e_j|) to its last node and minus that to its first. Zero on a straight
/// rod: twisting alone does not move the nodes.
void intervalTwistGradient(const Rod& rod, int s, const NodeArray& x, NodeArray& gradient);

/// Adds the rod's twisting forces -(G J twist / L) d(twist)/dx [N] at x to `force` (3 x the model's nodes),
/// each interval's twist counted at x on from its entry of State::twist `twist`.
void accumulateTwistForces(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, NodeArray& force);

/// Bending plus twisting energy [J] of the rod at x with the twists of State::twist `twist`:
///   sum over vertices of weight |kb|^2  +  sum over intervals of G J twist^2 / (2 L_interval).
double rodEnergy(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist);

/// Adds the rod's bending and twisting forces -dE/dx [N] at x to `force` (3 x the model's nodes):
/// -2 weight J_k^T kb at each vertex's nodes (J_k = dkb/dx_k), and -(G J twist / L) d(twist)/dx per
/// interval.
void accumulateRodForces(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, NodeArray& force);

/// Adds the rod's end moment (Rod::end_moment) at x to `force` (3 x the model's nodes): the couple
/// F = M x e / |e|^2 on its last node and -F on the one before (e the last segment), whose moment is M's
/// part across e. In a plane it is -d(-M theta)/dx for theta the last segment's angle: a dead moment.
void accumulateRodEndMoment(const Rod& rod, const NodeArray& x, NodeArray& force);

/// Each segment's material frame at x (count - 1 of them): x along the segment; between two stations the
/// earlier station's leaving frame carried by parallel transport and turned about the segment by the
/// interval's twist times its midpoint's share of the interval; beyond the outer stations the frame
/// carried from them untwisted (a free end); a rod without stations carries its rest frame.
void rodFrames(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, std::vector<Eigen::Quaterniond>& frames);

/// The torque [N m] the rod exerts on station s at x, beyond its nodes' forces: at a station of one node
/// its bending moment there, l (g x a) per ghost edge with g = dE/d(ghost edge) and a the held axis; and the
/// twisting moments of the intervals on each side, -G J twist / L about the entering axis (the interval
/// before) and +G J twist / L about the leaving axis (the one after). The twists' dependence on the held
/// axes' directions (their holonomy through the station) is not included.
Vec3 stationTorque(const Rod& rod, int s, const NodeArray& x, const Eigen::VectorXd& twist);

/// Makes node `node` (global) of the rod a station of one node in the rest frame, held by a holder at rest
/// (a clamp, a scene's anchor: RodStation::turn with its orientation); nothing if it is one already. For
/// a rod at rest, before it steps.
void clampRod(Rod& rod, int node);

/// Holds nodes first .. last of the rod (pinned by the caller) as a new station, held by a holder at
/// orientation `holder` (unit) now: the station keeps the material frames the rod has there now (rodFrames;
/// at a station of one node, turned onto the mean of its two segments' directions) and turns with the
/// holder (RodStation::turn). The interval it falls in splits in two, each twist counted on from its share
/// of the old one. Returns the new station's index. Throws std::invalid_argument if the nodes overlap a
/// station.
int holdRod(Rod& rod, const NodeArray& x, Eigen::VectorXd& twist, int first, int last, const Eigen::Quaterniond& holder);

/// Lets station s go: the intervals on each side join, their twist the sum of theirs and the station's own
/// (between its two frames).
void releaseRod(Rod& rod, const NodeArray& x, Eigen::VectorXd& twist, int s);

}  // namespace soft_body_sim
