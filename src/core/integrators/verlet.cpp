#include "integrator_kit.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
/// Position (Stoermer) Verlet as Jakobsen uses it, with constraint relaxation after the move:
///   x_{n+1} = 2 x_n - x_{n-1} + h^2 a(x_n, v_n)
/// Started with second-order accuracy, x_1 = x_0 + h v_0 + h^2/2 a_0. Damping and drag need a
/// velocity, estimated from positions to second order:
///   v_{n+1} = (x_{n+1} - x_n) / h + h/2 a_n
/// (Taylor: (x_{n+1} - x_n)/h = v_{n+1} - h/2 a_{n+1} + O(h^2) and a_{n+1} = a_n + O(h)).
/// The recurrence needs a constant h: a new h restarts it from (x, v).
class Verlet final : public Integrator
{
public:
  void step(const Model& model, State& state, double h, int iterations) override
  {
    if (has_history_ && h != h_)
      has_history_ = false;
    computeAccelerations(model, state.position, state.velocity, force_, acceleration_);
    if (!has_history_)
      previous_ = state.position;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      const Vec3 x = state.position.col(i);
      const Vec3 displacement = has_history_ ? Vec3(x - previous_.col(i)) : Vec3(h * state.velocity.col(i));
      const double a_factor = has_history_ ? h * h : 0.5 * h * h;
      state.position.col(i) = x + displacement + a_factor * acceleration_.col(i);
      previous_.col(i) = x;
    }
    projectConstraints(model, h, iterations, previous_, state.position, lambda_);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) = (state.position.col(i) - previous_.col(i)) / h + 0.5 * h * acceleration_.col(i);
    has_history_ = true;
    h_ = h;
  }

  void restart() override { has_history_ = false; }

private:
  bool has_history_ = false;
  double h_ = 0.0;
  NodeArray previous_;  ///< x_{n-1} [m] (pinned columns unused)
  NodeArray force_;
  NodeArray acceleration_;
  Eigen::VectorXd lambda_;
};
}  // namespace

std::unique_ptr<Integrator> makeVerlet() { return std::make_unique<Verlet>(); }

}  // namespace soft_body_sim
