#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// Velocity Verlet (kick-drift-kick):
///   v_{n+1/2} = v_n + h/2 a_n,   x_{n+1} = x_n + h v_{n+1/2},   v_{n+1} = v_{n+1/2} + h/2 a_{n+1}
/// a_{n+1} depends on v_{n+1} through damping and drag; it is evaluated at the predictor
/// v_n + h a_n, whose O(h^2) error enters v_{n+1} as O(h^3), keeping the scheme second order with
/// one force evaluation per step. a_{n+1} is reused as the next step's a_n.
class VelocityVerlet final : public ForceBasedIntegrator
{
public:
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<VelocityVerlet>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  void carry(StateArchive& archive, const Model& model) override
  {
    ForceBasedIntegrator::carry(archive, model);
    archive(has_acceleration_, acceleration_);
  }
  void step(const Model& model, State& state, double h, int iterations) override
  {
    if (!has_acceleration_)
      accelerations(model, state.position, state.velocity, force_, acceleration_);
    predicted_velocity_ = state.velocity;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      predicted_velocity_.col(i) += h * acceleration_.col(i);
      state.velocity.col(i) += 0.5 * h * acceleration_.col(i);
      state.position.col(i) += h * state.velocity.col(i);
    }
    accelerations(model, state.position, predicted_velocity_, force_, acceleration_);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) += 0.5 * h * acceleration_.col(i);
    constraints_.apply(model, state, h, iterations);
    // A constraint projection changes the state after a_{n+1} was taken: evaluate afresh then.
    has_acceleration_ = model.constraints.empty();
  }

  void invalidate() override { has_acceleration_ = false; }

private:
  bool has_acceleration_ = false;
  NodeArray force_;
  NodeArray acceleration_;
  NodeArray predicted_velocity_;
};
}  // namespace

std::unique_ptr<Integrator> makeVelocityVerlet() { return std::make_unique<VelocityVerlet>(); }

}  // namespace soft_body_sim
