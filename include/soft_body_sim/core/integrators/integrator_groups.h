// Which integrator steps which body. Every body starts on the scene's integrator; the divergence guard
// may move one body to another (guard.h). While all bodies share one integrator it steps the whole model;
// otherwise each integrator gets a group: a copy of the model in which the other groups' nodes are pinned
// (their positions and velocities belong to their own group, as an anchor's to us).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class IntegratorGroups
{
public:
  IntegratorGroups(IntegratorType scene_type, std::size_t bodies);
  /// Every integrator cloned (Integrator::clone): the copy steps on as the original would.
  IntegratorGroups(const IntegratorGroups& other);
  IntegratorGroups(IntegratorGroups&&) = default;
  IntegratorGroups& operator=(IntegratorGroups&&) = default;
  /// As the copy; integrators of the same kinds in the same groups take the other's state into their
  /// own buffers (Integrator::assign).
  IntegratorGroups& operator=(const IntegratorGroups& other);

  /// The scene's integrator (setAll's).
  IntegratorType sceneType() const { return scene_type_; }
  /// The integrator stepping body `body` (index into Model::bodies).
  IntegratorType bodyType(std::size_t body) const { return body_type_.at(body); }

  /// Every body on `type` from now on; the new integrator starts from the current x, v.
  void setAll(IntegratorType type);
  /// Body `body` alone on `type` from the next step on (the guard's switch).
  void switchBody(std::size_t body, IntegratorType type);

  /// Makes the groups again if a switch or a model change asked for it (the first stage of a step).
  void prepare(const Model& model);
  /// Advances every free node of `state` by one sub-step h [s], among the colliders `contacts` (null:
  /// none).
  void step(const Model& model, State& state, double h, int iterations, ContactQuery* contacts);

  /// The forces inside the bodies in the last sub-step, each link's and cell's by the integrator stepping it
  /// (Integrator::internalForces); one between two groups by the last of them.
  void internalForces(const Model& model, const State& state, InternalForces& forces) const;

  /// The state was changed from outside the integrators: they drop what they cached from it.
  void invalidate();
  /// The model was changed: they drop what they cached from it, and the groups are made again.
  void modelChanged();

  /// Writes or reads which body each integrator steps and each integrator's carried state
  /// (state_archive.h); `model` is the world's, read already. Read, the groups are made again from it as
  /// they were made from it (a change of the model since would have asked for that anyway).
  void carry(StateArchive& archive, const Model& model);

private:
  struct Group
  {
    IntegratorType type;
    Model model;
    std::unique_ptr<Integrator> integrator;
    /// per element kind (element_kinds.h, in its order), per element of `model`: its index in the scene's
    std::vector<std::vector<std::size_t>> elements;
  };

  void rebuild(const Model& model);

  IntegratorType scene_type_;
  std::unique_ptr<Integrator> integrator_;  ///< steps the whole model while groups_ is empty
  std::vector<IntegratorType> body_type_;   ///< per body
  std::vector<Group> groups_;               ///< empty while every body uses scene_type_
  bool dirty_ = false;
};

}  // namespace soft_body_sim
