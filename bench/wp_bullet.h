// The peer: Bullet Physics' soft bodies (btSoftBody), a rope of CreateRope's nodes and links with
// kLST = 1 (and, where the problem asks, bending links to further neighbours), stepped as
// btDefaultSoftBodySolver steps it inside a btSoftRigidDynamicsWorld.
#pragma once

#include <memory>
#include <string>

#include "wp_engine.h"
#include "wp_problems.h"

namespace soft_body_sim::bench
{
/// True when the benchmark was built with Bullet (libbullet-dev found by pkg-config).
bool bulletAvailable();
/// "Bullet 3.24, double precision (BT_USE_DOUBLE_PRECISION)" or why it is absent.
std::string bulletDescription();
/// A Bullet rope run with dt = config.dt, piterations = config.iterations and its bending links' kLST =
/// config.bending_stiffness; nullptr without Bullet.
std::unique_ptr<Engine> makeBulletRope(const BulletRope& rope, const Config& config);

}  // namespace soft_body_sim::bench
