// The scene's names as Python looks them up: a name the scene does not know is a KeyError that lists the
// names it does know.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "soft_body_sim/core/world.h"

namespace soft_body_sim::python
{
/// A body, anchor, grasp or collider name the world does not know; what() names the known ones. The module
/// raises it as KeyError.
class UnknownName : public std::out_of_range
{
public:
  using std::out_of_range::out_of_range;
};

/// Index into model.bodies of body `body`; throws UnknownName.
std::size_t findBody(const Model& model, const std::string& body);
/// Index into model().anchors of anchor `anchor` of body `body`; throws UnknownName naming the body's
/// anchors (or the bodies, for an unknown body).
int findAnchor(const World& world, const std::string& body, const std::string& anchor);
/// Index into grasps() of the grasp of frame `frame`; throws UnknownName naming the grasps.
std::size_t findGrasp(const World& world, const std::string& frame);
/// The names of the colliders that move (spheres, capsules, boxes, cylinders, meshes: not planes).
std::vector<std::string> movableColliders(const Model& model);
/// "'a', 'b'" or "none".
std::string listed(const std::vector<std::string>& names);

}  // namespace soft_body_sim::python
