#include "integrator_kit.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
/// Symplectic (semi-implicit) Euler, the string tutorial's scheme with the step h it forgot:
///   v_{n+1} = v_n + h a(x_n, v_n),   x_{n+1} = x_n + h v_{n+1}
/// First order, symplectic: an undamped oscillator stays bounded for w h < 2.
class SemiImplicitEuler final : public Integrator
{
public:
  void step(const Model& model, State& state, double h, int iterations) override
  {
    computeAccelerations(model, state.position, state.velocity, force_, acceleration_);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      state.velocity.col(i) += h * acceleration_.col(i);
      state.position.col(i) += h * state.velocity.col(i);
    }
    constraints_.apply(model, state, h, iterations);
  }

private:
  NodeArray force_;
  NodeArray acceleration_;
  ConstraintPass constraints_;
};
}  // namespace

std::unique_ptr<Integrator> makeSemiImplicitEuler() { return std::make_unique<SemiImplicitEuler>(); }

}  // namespace soft_body_sim
