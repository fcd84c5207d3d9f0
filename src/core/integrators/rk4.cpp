#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// Classical fourth-order Runge-Kutta on y = (x, v), y' = (v, a(x, v)):
///   k1 = f(y_n), k2 = f(y_n + h/2 k1), k3 = f(y_n + h/2 k2), k4 = f(y_n + h k3),
///   y_{n+1} = y_n + h/6 (k1 + 2 k2 + 2 k3 + k4)
/// Stages move pinned nodes along their own (kinematic) velocity, so a moving anchor is seen where it
/// will be; the final update leaves them to the caller.
class Rk4 final : public ForceBasedIntegrator
{
public:
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<Rk4>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  void step(const Model& model, State& state, double h, int iterations) override
  {
    const NodeArray& x = state.position;
    const NodeArray& v = state.velocity;
    accelerations(model, x, v, force_, a1_);
    stage_x_ = x + 0.5 * h * v;
    v2_ = v + 0.5 * h * a1_;
    accelerations(model, stage_x_, v2_, force_, a2_);
    stage_x_ = x + 0.5 * h * v2_;
    v3_ = v + 0.5 * h * a2_;
    accelerations(model, stage_x_, v3_, force_, a3_);
    stage_x_ = x + h * v3_;
    v4_ = v + h * a3_;
    accelerations(model, stage_x_, v4_, force_, a4_);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      state.position.col(i) += (h / 6.0) * (v.col(i) + 2.0 * v2_.col(i) + 2.0 * v3_.col(i) + v4_.col(i));
      state.velocity.col(i) += (h / 6.0) * (a1_.col(i) + 2.0 * a2_.col(i) + 2.0 * a3_.col(i) + a4_.col(i));
    }
    constraints_.apply(model, state, h, iterations);
  }

private:
  NodeArray force_;
  NodeArray stage_x_;
  NodeArray v2_, v3_, v4_;
  NodeArray a1_, a2_, a3_, a4_;
};
}  // namespace

std::unique_ptr<Integrator> makeRk4() { return std::make_unique<Rk4>(); }

}  // namespace soft_body_sim
