#include "soft_body_sim/core/holding/anchors.h"

#include "soft_body_sim/core/elements/rods.h"

namespace soft_body_sim
{
AnchorSet::AnchorSet(std::size_t scene_anchors)
  : goals_(scene_anchors)
  , paths_(scene_anchors)
  , turns_(scene_anchors)
  , turned_from_(scene_anchors, Eigen::Quaterniond::Identity())
  , scene_anchors_(scene_anchors)
{
}

std::optional<int> AnchorSet::find(const Model& model, const std::string& body, const std::string& anchor)
{
  for (std::size_t k = 0; k < model.anchors.size(); ++k)
    if (model.anchors[k].body == body && model.anchors[k].name == anchor)
      return static_cast<int>(k);
  return std::nullopt;
}

void AnchorSet::goalsFromPaths(double t)
{
  for (std::size_t k = 0; k < goals_.size(); ++k)
    if (paths_[k] && !goals_[k])
      goals_[k] = paths_[k](t);
}

bool AnchorSet::setVelocities(const Model& model, State& state, double dt)
{
  bool moved = false;
  for (std::size_t k = 0; k < model.anchors.size(); ++k)
  {
    const int node = model.anchors[k].node;
    if (const StationIndex at = turns_[k] ? findRodStation(model, node) : StationIndex{})
    {
      const RodStation& station = rodStation(model, at);
      turned_from_[k] = station.frame[0] * station.held[0].conjugate();
      moved = true;
    }
    if (goals_[k])
    {
      state.velocity.col(node) = (*goals_[k] - state.position.col(node)) / dt;
      moved = true;
    }
    else if (!state.velocity.col(node).isZero(0.0))
    {
      // It arrived last step and stands still now.
      state.velocity.col(node).setZero();
      moved = true;
    }
  }
  return moved;
}

void AnchorSet::advance(Model& model, State& state, int substep, int substeps, double h) const
{
  for (std::size_t k = 0; k < model.anchors.size(); ++k)
  {
    const int node = model.anchors[k].node;
    state.position.col(node) += h * state.velocity.col(node);
    if (const StationIndex at = turns_[k] ? findRodStation(model, node) : StationIndex{})
      rodStation(model, at).turn(turned_from_[k].slerp(static_cast<double>(substep) / substeps, *turns_[k]));
  }
}

void AnchorSet::land(Model& model, State& state)
{
  for (std::size_t k = 0; k < model.anchors.size(); ++k)
  {
    if (goals_[k])
    {
      state.position.col(model.anchors[k].node) = *goals_[k];
      goals_[k].reset();
    }
    if (const StationIndex at = turns_[k] ? findRodStation(model, model.anchors[k].node) : StationIndex{})
      rodStation(model, at).turn(*turns_[k]);
    turns_[k].reset();
  }
}

void AnchorSet::added()
{
  goals_.emplace_back();
  paths_.emplace_back();
  turns_.emplace_back();
  turned_from_.push_back(Eigen::Quaterniond::Identity());
}

void AnchorSet::removed(std::size_t k)
{
  goals_.erase(goals_.begin() + static_cast<std::ptrdiff_t>(k));
  paths_.erase(paths_.begin() + static_cast<std::ptrdiff_t>(k));
  turns_.erase(turns_.begin() + static_cast<std::ptrdiff_t>(k));
  turned_from_.erase(turned_from_.begin() + static_cast<std::ptrdiff_t>(k));
}

void AnchorSet::carry(StateArchive& archive)
{
  archive(goals_, turns_, turned_from_, scene_anchors_);
  if (archive.reading())
  {
    paths_.resize(scene_anchors_);
    paths_.resize(goals_.size());
  }
}

bool AnchorSet::isAttached(int k) const
{
  return k >= 0 && static_cast<std::size_t>(k) >= scene_anchors_ && static_cast<std::size_t>(k) < goals_.size();
}

}  // namespace soft_body_sim
