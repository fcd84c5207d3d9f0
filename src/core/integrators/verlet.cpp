#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// Position (Stoermer) Verlet as Jakobsen uses it, with constraint relaxation after the move:
///   x_{n+1} = 2 x_n - x_{n-1} + h^2 a(x_n, v_n)
/// Damping and drag need a velocity, estimated from positions to second order:
///   v_n = (x_n - x_{n-1}) / h + h/2 a_{n-1}
/// (Taylor: (x_n - x_{n-1})/h = v_n - h/2 a_n + O(h^2) and a_n = a_{n-1} + O(h)). The history
/// x_{n-1} is kept through that estimate, x_n - x_{n-1} = h v_n - h^2/2 a_{n-1}, so the update reads
///   x_{n+1} = x_n + h v_n + h^2 (a_n - a_{n-1} / 2)
/// which is the same recurrence, and a velocity changed from outside (a plane contact, an anchor's
/// pull) enters the next step as it should. Started with second-order accuracy: a_{-1} = a_0 gives
/// x_1 = x_0 + h v_0 + h^2/2 a_0. The recurrence needs a constant h: a new h starts it again.
class Verlet final : public ForceBasedIntegrator
{
public:
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<Verlet>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  void carry(StateArchive& archive, const Model& model) override
  {
    ForceBasedIntegrator::carry(archive, model);
    archive(has_history_, h_, previous_acceleration_);
  }
  void step(const Model& model, State& state, double h, int iterations) override
  {
    accelerations(model, state.position, state.velocity, force_, acceleration_);
    if (!has_history_ || h != h_)
      previous_acceleration_ = acceleration_;
    start_ = state.position;
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.position.col(i) +=
            h * state.velocity.col(i) + h * h * (acceleration_.col(i) - 0.5 * previous_acceleration_.col(i));
    constraints_.project(model, h, iterations, start_, state.position);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) = (state.position.col(i) - start_.col(i)) / h + 0.5 * h * acceleration_.col(i);
    previous_acceleration_.swap(acceleration_);
    has_history_ = true;
    h_ = h;
  }

private:
  bool has_history_ = false;
  double h_ = 0.0;
  NodeArray start_;                  ///< x_n [m]
  NodeArray force_;
  NodeArray acceleration_;           ///< a_n [m/s^2]
  NodeArray previous_acceleration_;  ///< a_{n-1} [m/s^2]
};
}  // namespace

std::unique_ptr<Integrator> makeVerlet() { return std::make_unique<Verlet>(); }

}  // namespace soft_body_sim
