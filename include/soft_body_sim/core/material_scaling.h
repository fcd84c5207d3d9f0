// Live material: what each body was built with, and the factors a user turns on it while the scene runs
// (the jelly seed's sliders "to make it more springy or viscous"). The factors multiply the built values,
// so they never compound and 1 restores the scene.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Live multipliers of one body's material, relative to the scene's values. 1 = as loaded; each > 0.
struct BodyScaling
{
  double stiffness = 1.0;  ///< [-] spring stiffness k, constraint stiffness 1 / compliance, a rod's E I and G J, a solid's E
  double damping = 1.0;    ///< [-] spring dashpots c, a rod's damping beta
  double pressure = 1.0;   ///< [-] rest gas pressure p0 of the body's cells and tetrahedra

  void carry(StateArchive& archive) { archive(stiffness, damping, pressure); }
};

/// The values the factors multiply are the elements as built. While every factor is 1 the model's own
/// elements are those values, so no copy of them is kept (a cloth's springs are 190 bytes a node): the
/// copy is made when a factor other than 1 is first set, or when a snapshot's bytes bring one. Only the
/// kinds whose elements change as a body is held (a rod's stations) are kept from the start.
class MaterialScaling
{
public:
  /// For a model as built: keeps what holding changes of it (see the class comment).
  explicit MaterialScaling(const Model& built);

  /// Writes body `body`'s elements into `model` as built times `scaling` (each kind's scale). Throws
  /// std::invalid_argument if a factor is out of range (see BodyScaling) and changes nothing then.
  void set(Model& model, std::size_t body, const BodyScaling& scaling);
  /// Keeps a copy of `model`'s elements as built if none is kept yet (every factor is 1, so they are).
  void keepBuilt(const Model& model);
  /// After factors were read (carry) into a copy of a world whose model is `before` (untouched by the
  /// read): keeps the elements as built from `before` if a factor is not 1, else drops any copy (the model
  /// read is as built then).
  void factorsRead(const Model& before);
  /// The scaling last set for body `body` (all 1 if never set).
  const BodyScaling& of(std::size_t body) const { return scaling_.at(body); }
  /// True if body `body` was built with elements of any kind: a material to scale.
  bool has(std::size_t body) const { return has_material_.at(body) != 0; }
  /// Writes every kind's elements as built into `into`'s element arrays (`model` is the live model).
  void builtElements(const Model& model, Model& into) const;

  /// Writes or reads the factors (state_archive.h); what they multiply is the scene's.
  void carry(StateArchive& archive) { archive(scaling_); }

private:
  /// The elements as built (its element arrays only: the kinds that change as held, and all of them while
  /// all_kept_); never changed, so copies of a world share it.
  std::shared_ptr<const Model> built_;
  bool all_kept_ = false;
  std::vector<BodyScaling> scaling_;  ///< per body
  std::vector<char> has_material_;    ///< per body
};

}  // namespace soft_body_sim
