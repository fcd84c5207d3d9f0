#include "soft_body_sim/core/bodies/humanoid.h"

#include <array>
#include <memory>
#include <stdexcept>

#include <Eigen/Geometry>  // cross products

#include "core/bodies/fixed_period_clock.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
namespace
{
constexpr std::array<int, 4> kLimbRoots = { kHumanoidLeftArm, kHumanoidRightArm, kHumanoidLeftLeg,
                                            kHumanoidRightLeg };

/// Where the torso's nodes and the limbs' roots sit relative to the pelvis [m].
struct TorsoFrame
{
  Vec3 up;
  Vec3 left;
  std::array<Vec3, kHumanoidNodes> offset;  ///< set for the pelvis, neck, head and the four roots
};

TorsoFrame torsoFrame(const HumanoidDef& def)
{
  TorsoFrame frame;
  frame.up = def.up.normalized();
  frame.left = frame.up.cross(def.facing).normalized();
  frame.offset.fill(Vec3::Zero());
  const Vec3 neck = def.torso_length * frame.up;
  frame.offset[kHumanoidNeck] = neck;
  frame.offset[kHumanoidHead] = neck + def.head_height * frame.up;
  frame.offset[kHumanoidLeftArm] = neck + 0.5 * def.shoulder_width * frame.left;
  frame.offset[kHumanoidRightArm] = neck - 0.5 * def.shoulder_width * frame.left;
  frame.offset[kHumanoidLeftLeg] = 0.5 * def.hip_width * frame.left;
  frame.offset[kHumanoidRightLeg] = -0.5 * def.hip_width * frame.left;
  return frame;
}

bool isArm(int root) { return root == kHumanoidLeftArm || root == kHumanoidRightArm; }

class HumanoidController final : public Controller
{
public:
  std::unique_ptr<Controller> clone() const override { return std::make_unique<HumanoidController>(*this); }
  void carry(StateArchive& archive) override
  {
    archive(clock_, pelvis_, pelvis_previous_, pelvis_from_, target_, limbs_, joint_from_, leaf_from_);
  }
  HumanoidController(const HumanoidDef& def, const TorsoFrame& frame, int first_node)
    : def_(def)
    , frame_(frame)
    , first_node_(first_node)
    , clock_(def.limbs.frame_period, def.limbs.max_frames_per_step)
    , pelvis_(def.position)
    , pelvis_previous_(def.position)
    , pelvis_from_(def.position)
    , target_(def.target.value_or(def.position))
  {
    for (std::size_t k = 0; k < kLimbRoots.size(); ++k)
    {
      const int root = kLimbRoots[k];
      const double half = 0.5 * (isArm(root) ? def.arm_length : def.leg_length);
      const Vec3 joint = def.position + frame.offset[root] - half * frame.up;
      const Vec3 leaf = joint - half * frame.up;
      limbs_[k].emplace(def.limbs, half, half, joint, leaf);
      joint_from_[k] = joint;
      leaf_from_[k] = leaf;
    }
  }

  /// Keeps the figure one frame ahead of its own time and draws it on the straight line between the
  /// frames around it; the torso's nodes and the roots are the pelvis plus fixed offsets.
  void step(double dt, State& state) override
  {
    clock_.run(
        dt,
        [&] {
          pelvis_from_ = pelvis_;
          for (std::size_t k = 0; k < limbs_.size(); ++k)
          {
            joint_from_[k] = limbs_[k]->joint();
            leaf_from_[k] = limbs_[k]->leaf();
          }
        },
        [&] { update(); });
    const double phase = clock_.phase();
    const double period = clock_.period();
    const Vec3 pelvis_velocity = (pelvis_ - pelvis_from_) / period;
    const Vec3 pelvis = pelvis_from_ + phase * (pelvis_ - pelvis_from_);
    for (const int node : { kHumanoidPelvis, kHumanoidNeck, kHumanoidHead })
      set(state, node, pelvis + frame_.offset[node], pelvis_velocity);
    for (std::size_t k = 0; k < limbs_.size(); ++k)
    {
      const int root = kLimbRoots[k];
      set(state, root + kLimbRoot, pelvis + frame_.offset[root], pelvis_velocity);
      drawBetween(state, first_node_ + root + kLimbJoint, joint_from_[k], limbs_[k]->joint(), phase, period);
      drawBetween(state, first_node_ + root + kLimbLeaf, leaf_from_[k], limbs_[k]->leaf(), phase, period);
    }
  }

  bool takesTarget() const override { return true; }

  bool setTarget(const Vec3& target) override
  {
    target_ = target;
    return true;
  }

  std::optional<Vec3> target() const override { return target_; }

  /// The spine (pelvis, neck, head), the shoulders, the hips and the four limbs' Bezier curves.
  std::vector<std::vector<Vec3>> curves(const State& state) const override
  {
    const auto at = [&](int node) { return Vec3(state.position.col(first_node_ + node)); };
    std::vector<std::vector<Vec3>> lines = {
      { at(kHumanoidPelvis), at(kHumanoidNeck), at(kHumanoidHead) },
      { at(kHumanoidLeftArm), at(kHumanoidNeck), at(kHumanoidRightArm) },
      { at(kHumanoidLeftLeg), at(kHumanoidPelvis), at(kHumanoidRightLeg) },
    };
    for (const int root : kLimbRoots)
      lines.push_back(limbCurve(state, first_node_ + root, def_.limbs.curve_samples));
    return lines;
  }

private:
  void set(State& state, int node, const Vec3& position, const Vec3& velocity) const
  {
    state.position.col(first_node_ + node) = position;
    state.velocity.col(first_node_ + node) = velocity;
  }

  /// One frame: the pelvis's Jakobsen spring step, then each limb with its root at the new attachment.
  void update()
  {
    const double h = def_.limbs.frame_period;
    const Vec3 next =
        pelvis_ + def_.torso_retention * (pelvis_ - pelvis_previous_) + (def_.torso_stiffness * h * h) * (target_ - pelvis_);
    pelvis_previous_ = pelvis_;
    pelvis_ = next;
    for (std::size_t k = 0; k < limbs_.size(); ++k)
      limbs_[k]->update(pelvis_ + frame_.offset[kLimbRoots[k]]);
  }

  HumanoidDef def_;
  TorsoFrame frame_;
  int first_node_;
  FixedPeriodClock clock_;
  Vec3 pelvis_;           ///< at the next frame instant [m]
  Vec3 pelvis_previous_;  ///< one frame earlier (Verlet history)
  Vec3 pelvis_from_;      ///< at the last frame instant passed
  Vec3 target_;
  std::array<std::optional<LimbDynamics>, 4> limbs_;  ///< left arm, right arm, left leg, right leg
  std::array<Vec3, 4> joint_from_;
  std::array<Vec3, 4> leaf_from_;
};

}  // namespace

BodyDef buildHumanoid(const std::string& name, const HumanoidDef& def)
{
  const std::string what = "humanoid '" + name + "'";
  const auto check = [&what](bool ok, std::vector<std::string> keys, const std::string& reason) {
    requireDefinition(ok, what, std::move(keys), reason);
  };
  checkLimbMotion(def.limbs, what);
  for (const auto& [key, value] : { std::pair{ "torso_length", def.torso_length },
                                    std::pair{ "head_height", def.head_height },
                                    std::pair{ "shoulder_width", def.shoulder_width },
                                    std::pair{ "hip_width", def.hip_width }, std::pair{ "arm_length", def.arm_length },
                                    std::pair{ "leg_length", def.leg_length } })
    check(value > 0.0, { key }, std::string(key) + " must be > 0");
  check(def.torso_stiffness >= 0.0, { "torso_stiffness" }, "torso_stiffness must be >= 0");
  check(def.torso_retention >= 0.0 && def.torso_retention <= 1.0, { "torso_retention" },
        "torso_retention must be in [0, 1]");
  // The pelvis's recurrence is the creature lead's: stable for k T^2 < 2 (1 + r).
  const double k_t2 = def.torso_stiffness * def.limbs.frame_period * def.limbs.frame_period;
  check(k_t2 < 2.0 * (1.0 + def.torso_retention), { "torso_stiffness", "frame_period", "torso_retention" },
        "torso_stiffness * frame_period^2 = " + formatNumber(k_t2) + " must be < 2 (1 + torso_retention) = " +
            formatNumber(2.0 * (1.0 + def.torso_retention)) + " for the torso's recurrence to be stable");
  check(def.up.norm() > 1e-12, { "up" }, "up must not be zero");
  check(def.facing.norm() > 1e-12, { "facing" }, "facing must not be zero");
  check(def.up.normalized().cross(def.facing.normalized()).norm() > 1e-9, { "facing", "up" },
        "facing must not be parallel to up");

  const TorsoFrame frame = torsoFrame(def);
  BodyDef body;
  body.name = name;
  body.type = "humanoid";
  body.nodes.resize(kHumanoidNodes, NodeDef{ def.position, 0.01, Vec3::Zero(), true });
  for (const int node : { kHumanoidPelvis, kHumanoidNeck, kHumanoidHead })
    body.nodes[static_cast<std::size_t>(node)].position = def.position + frame.offset[node];
  for (const int root : kLimbRoots)
  {
    const double half = 0.5 * (isArm(root) ? def.arm_length : def.leg_length);
    const Vec3 start = def.position + frame.offset[root];
    body.nodes[static_cast<std::size_t>(root + kLimbRoot)].position = start;
    body.nodes[static_cast<std::size_t>(root + kLimbJoint)].position = start - half * frame.up;
    body.nodes[static_cast<std::size_t>(root + kLimbLeaf)].position = start - 2.0 * half * frame.up;
  }
  body.controller = [def, frame](int first_node) {
    return std::make_unique<HumanoidController>(def, frame, first_node);
  };
  return body;
}

}  // namespace soft_body_sim
