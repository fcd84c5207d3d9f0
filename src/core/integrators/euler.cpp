#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// The two first-order Euler schemes, which differ only in which of position and velocity moves first:
///  - explicit (forward) Euler, in the order of the TUM tutorial: positions move with the old velocity,
///    then the velocity takes the acceleration of the old state,
///      x_{n+1} = x_n + h v_n,   v_{n+1} = v_n + h a(x_n, v_n);
///    it multiplies an undamped oscillator's energy by (1 + w^2 h^2) every step;
///  - symplectic (semi-implicit) Euler, the string tutorial's scheme with the step h it forgot,
///      v_{n+1} = v_n + h a(x_n, v_n),   x_{n+1} = x_n + h v_{n+1};
///    an undamped oscillator stays bounded for w h < 2.
template <bool kVelocityFirst>
class Euler final : public ForceBasedIntegrator
{
public:
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<Euler>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  void step(const Model& model, State& state, double h, int iterations) override
  {
    accelerations(model, state.position, state.velocity, force_, acceleration_);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      if (kVelocityFirst)
        state.velocity.col(i) += h * acceleration_.col(i);
      state.position.col(i) += h * state.velocity.col(i);
      if (!kVelocityFirst)
        state.velocity.col(i) += h * acceleration_.col(i);
    }
    constraints_.apply(model, state, h, iterations);
  }

private:
  NodeArray force_;
  NodeArray acceleration_;
};
}  // namespace

std::unique_ptr<Integrator> makeExplicitEuler() { return std::make_unique<Euler<false>>(); }
std::unique_ptr<Integrator> makeSemiImplicitEuler() { return std::make_unique<Euler<true>>(); }

}  // namespace soft_body_sim
