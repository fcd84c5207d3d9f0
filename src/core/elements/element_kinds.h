// Every kind of element a Model holds, one unit each (its file in this folder), registered once here.
// What the core does with "all the elements" (their energy, their pulls on what holds them, a body's live
// material, which integrator group an element joins, which integrators run a scene) is one loop over
// ElementKinds: a kind added here reaches every consumer, and a kind that lacks something a consumer asks of
// it does not compile.
//
// A kind is a struct of static members (no per-element virtual call in any loop):
//   using Element;                                  the element's plain struct (model.h)
//   kName                                           what a message calls them ("tetrahedra")
//   of(Model&), of(const Model&)                    the model's array of them
//   bodyNode(e)                                     a node of e, which tells its body (an element lies in one body)
//   touches(e, mine)                                whether e acts on a node for which mine(node) holds
//   runsUnder(IntegratorType)                       whether that integrator steps this kind
//   kChangesAsHeld                                  whether holding a body changes its elements (a rod's stations)
//   energy(e, state)                                its stored energy [J] (elastic, or its gas's)
//   scale(e, built, scaling)                        e as built times a body's live factors (BodyScaling)
//   addPulls(model, state, forces, pull)            its forces on the nodes [N] (reactions.h), all elements
// Implicit Euler's blocks of a kind live in integrators/implicit_euler/ (one file per kind there too).
#pragma once

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>

#include "core/elements/distance_constraint_kind.h"
#include "core/elements/gas_cell_kind.h"
#include "core/elements/rod_kind.h"
#include "core/elements/spring_kind.h"
#include "core/elements/tetrahedron_kind.h"

namespace soft_body_sim
{
template <class... Kinds>
struct KindList
{
  static constexpr std::size_t size = sizeof...(Kinds);
};

/// The registry: every element kind, in the order the core sums them.
using ElementKinds = KindList<SpringKind, DistanceConstraintKind, GasCellKind, RodKind, TetrahedronKind>;

/// Kind's position in ElementKinds.
template <class Kind, class... Kinds>
constexpr std::size_t kindIndex(KindList<Kinds...>)
{
  std::size_t index = 0, found = sizeof...(Kinds);
  ((std::is_same_v<Kind, Kinds> ? (found = index, ++index) : ++index), ...);
  return found;
}
template <class Kind>
constexpr std::size_t kindIndex()
{
  constexpr std::size_t index = kindIndex<Kind>(ElementKinds{});
  static_assert(index < ElementKinds::size, "not a registered element kind");
  return index;
}

/// Calls f(Kind{}) for every kind of ElementKinds, in order.
template <class F, class... Kinds>
void forEachKind(KindList<Kinds...>, F&& f)
{
  (f(Kinds{}), ...);
}
template <class F>
void forEachKind(F&& f)
{
  forEachKind(ElementKinds{}, std::forward<F>(f));
}

/// Throws std::invalid_argument naming each element kind of `model` that `integrator` does not run and the
/// integrators that do (a rod or a soft solid runs only under implicit_euler): the one rule, for the scene
/// as built and for a switch of a running one.
void requireIntegratorRunsModel(const Model& model, IntegratorType integrator);

}  // namespace soft_body_sim
