#include "soft_body_sim/core/material_scaling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/elements/element_kinds.h"

namespace soft_body_sim
{
namespace
{
bool unit(const BodyScaling& scaling)
{
  return scaling.stiffness == 1.0 && scaling.damping == 1.0 && scaling.pressure == 1.0;
}

/// The element arrays of `built` of the kinds kept from the start (kChangesAsHeld), the others empty.
std::shared_ptr<const Model> changingAsHeld(const Model& built)
{
  auto elements = std::make_shared<Model>();
  forEachKind([&](auto kind) {
    if (kind.kChangesAsHeld)
      kind.of(*elements) = kind.of(built);
  });
  return elements;
}
}  // namespace

MaterialScaling::MaterialScaling(const Model& built)
  : built_(changingAsHeld(built)), scaling_(built.bodies.size()), has_material_(built.bodies.size(), 0)
{
  forEachKind([&](auto kind) {
    for (const auto& element : kind.of(built))
      has_material_[built.bodyOf(kind.bodyNode(element))] = 1;
  });
}

void MaterialScaling::keepBuilt(const Model& model)
{
  if (all_kept_)
    return;
  auto elements = std::make_shared<Model>();
  forEachKind([&](auto kind) { kind.of(*elements) = kind.kChangesAsHeld ? kind.of(*built_) : kind.of(model); });
  built_ = std::move(elements);
  all_kept_ = true;
}

void MaterialScaling::factorsRead(const Model& before)
{
  if (!std::all_of(scaling_.begin(), scaling_.end(), unit))
    keepBuilt(before);
  else if (all_kept_)
  {
    built_ = changingAsHeld(*built_);
    all_kept_ = false;
  }
}

void MaterialScaling::builtElements(const Model& model, Model& into) const
{
  forEachKind([&](auto kind) { kind.of(into) = kind.kChangesAsHeld || all_kept_ ? kind.of(*built_) : kind.of(model); });
}

void MaterialScaling::set(Model& model, std::size_t body, const BodyScaling& scaling)
{
  // Stiffness and pressure divide (compliance = 1 / k, Boyle's law p0 A0 / A): they must stay > 0.
  if (!(scaling.stiffness > 0.0 && std::isfinite(scaling.stiffness)) ||
      !(scaling.pressure > 0.0 && std::isfinite(scaling.pressure)) ||
      !(scaling.damping >= 0.0 && std::isfinite(scaling.damping)))
    throw std::invalid_argument("World: body scaling: stiffness and pressure must be finite and > 0, damping >= 0");
  if (!all_kept_ && unit(scaling))
  {
    scaling_.at(body) = scaling;  // every factor 1 before and after: the model is as built
    return;
  }
  keepBuilt(model);
  scaling_.at(body) = scaling;
  // From the built values, not the current ones: factors do not compound and 1 restores the scene.
  forEachKind([&](auto kind) {
    auto& live = kind.of(model);
    const auto& built = kind.of(*built_);
    for (std::size_t k = 0; k < live.size(); ++k)
      if (model.bodyOf(kind.bodyNode(built[k])) == body)
        kind.scale(live[k], built[k], scaling);
  });
}

}  // namespace soft_body_sim
