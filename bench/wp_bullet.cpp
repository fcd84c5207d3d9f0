#include "wp_bullet.h"

#include <cmath>

#ifdef SOFT_BODY_SIM_WITH_BULLET
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <LinearMath/btScalar.h>
#endif

namespace soft_body_sim::bench
{
#ifdef SOFT_BODY_SIM_WITH_BULLET
namespace
{
/// One btSoftBody. Its step is what btDefaultSoftBodySolver does for each soft body of a
/// btSoftRigidDynamicsWorld (predictMotion, solveConstraints, integrateMotion), without the rigid-body
/// pipeline of an empty world and without the world's float(timeStep) cast in predictMotion: Bullet at
/// its cheapest and most precise.
class BulletRopeEngine final : public Engine
{
public:
  BulletRopeEngine(const BulletRope& rope, const Config& config) : dt_(config.dt), positions_(3, rope.nodes)
  {
    info_.m_gravity = btVector3(0, 0, -rope.gravity);
    info_.air_density = 0;
    info_.m_sparsesdf.Initialize();
    // Straight along x and at rest: every link's rest length is length / (nodes - 1), like ours.
    body_.reset(btSoftBodyHelpers::CreateRope(info_, btVector3(0, 0, 0), btVector3(rope.length, 0, 0), rope.nodes - 2, 0));
    // Bending links take their rest length from the nodes now: straight, 2 l apart for d = 2.
    if (rope.bending_distance >= 2)
    {
      btSoftBody::Material* bending = body_->appendMaterial();
      bending->m_kLST = config.bending_stiffness;
      body_->generateBendingConstraints(rope.bending_distance, bending);
    }
    for (int i = 0; i < rope.nodes; ++i)
    {
      btSoftBody::Node& node = body_->m_nodes[i];
      node.m_x = node.m_q = btVector3(rope.start(0, i), rope.start(1, i), rope.start(2, i));
      node.m_v = btVector3(0, 0, 0);
      body_->setMass(i, rope.masses.empty() ? rope.node_mass : rope.masses[static_cast<std::size_t>(i)]);
    }
    for (int i : rope.pinned)
      body_->setMass(i, 0);
    body_->m_materials[0]->m_kLST = 1;
    body_->m_cfg.piterations = config.iterations;
    // Its velocity damping: v = (x - x_prev) / dt (1 - kDP) per step, our drag exp(-drag dt) per step.
    body_->m_cfg.kDP = 1.0 - std::exp(-rope.drag * dt_);
    if (body_->m_cfg.m_psequence.size() == 0)
      body_->setSolver(btSoftBody::eSolverPresets::Positions);
  }

  void step() override
  {
    body_->predictMotion(dt_);
    body_->solveConstraints();
    body_->integrateMotion();
  }

  const Eigen::Matrix3Xd& positions() override
  {
    for (int i = 0; i < body_->m_nodes.size(); ++i)
    {
      const btVector3& x = body_->m_nodes[i].m_x;
      positions_.col(i) = Vec3(x.x(), x.y(), x.z());
    }
    return positions_;
  }

private:
  btScalar dt_;
  btSoftBodyWorldInfo info_;
  std::unique_ptr<btSoftBody> body_;
  Eigen::Matrix3Xd positions_;
};
}  // namespace

bool bulletAvailable() { return true; }

std::string bulletDescription()
{
  return std::string("Bullet ") + std::to_string(btGetVersion() / 100) + "." + std::to_string(btGetVersion() % 100) +
         (sizeof(btScalar) == sizeof(double) ? ", double precision (BT_USE_DOUBLE_PRECISION)" : ", single precision");
}

std::unique_ptr<Engine> makeBulletRope(const BulletRope& rope, const Config& config)
{
  return std::make_unique<BulletRopeEngine>(rope, config);
}
#else
bool bulletAvailable() { return false; }
std::string bulletDescription() { return "Bullet not built in (libbullet-dev not found at configure time): peer skipped"; }
std::unique_ptr<Engine> makeBulletRope(const BulletRope&, const Config&) { return nullptr; }
#endif

}  // namespace soft_body_sim::bench
