#include "soft_body_sim/core/bodies/limb.h"

#include <memory>
#include <stdexcept>

#include "core/bodies/fixed_period_clock.h"

namespace soft_body_sim
{
namespace
{
/// The seed's link relaxation on d = a - b: returns m = tension (L - |d|) / |d| d, to be added to a and
/// subtracted from b (only where they are free); zero for coincident ends (no direction).
Vec3 linkCorrection(const Vec3& a, const Vec3& b, double length, double tension)
{
  const Vec3 d = a - b;
  const double distance = d.norm();
  if (!(distance > 1e-12))
    return Vec3::Zero();
  return d * (tension * (length - distance) / distance);
}

class LimbController final : public Controller
{
public:
  std::unique_ptr<Controller> clone() const override { return std::make_unique<LimbController>(*this); }
  void carry(StateArchive& archive) override { archive(clock_, dynamics_, joint_from_, leaf_from_); }
  LimbController(const LimbDef& def, int first_node, const Vec3& joint, const Vec3& leaf)
    : first_node_(first_node)
    , samples_(def.motion.curve_samples)
    , clock_(def.motion.frame_period, def.motion.max_frames_per_step)
    , dynamics_(def.motion, def.upper_length, def.lower_length, joint, leaf)
    , joint_from_(joint)
    , leaf_from_(leaf)
  {
  }

  /// Keeps the limb one update ahead of its own time and draws joint and leaf on the straight line
  /// between the updates around it (exactly at update n at time n T).
  void step(double dt, State& state) override
  {
    const Vec3 root = state.position.col(first_node_ + kLimbRoot);
    clock_.run(
        dt,
        [&] {
          joint_from_ = dynamics_.joint();
          leaf_from_ = dynamics_.leaf();
        },
        [&] { dynamics_.update(root); });
    const double phase = clock_.phase();
    drawBetween(state, first_node_ + kLimbJoint, joint_from_, dynamics_.joint(), phase, clock_.period());
    drawBetween(state, first_node_ + kLimbLeaf, leaf_from_, dynamics_.leaf(), phase, clock_.period());
  }

  std::vector<std::vector<Vec3>> curves(const State& state) const override
  {
    return { limbCurve(state, first_node_, samples_) };
  }

private:
  int first_node_;
  int samples_;
  FixedPeriodClock clock_;
  LimbDynamics dynamics_;
  Vec3 joint_from_;  ///< joint at the last update instant passed [m]
  Vec3 leaf_from_;
};

}  // namespace

LimbDynamics::LimbDynamics(const LimbMotion& motion, double upper_length, double lower_length, const Vec3& joint,
                           const Vec3& leaf)
  : motion_(motion)
  , upper_length_(upper_length)
  , lower_length_(lower_length)
  , joint_(joint)
  , leaf_(leaf)
  , joint_previous_(joint)
  , leaf_previous_(leaf)
{
}

void LimbDynamics::update(const Vec3& root)
{
  const double h = motion_.frame_period;
  const Vec3 gravity_step = motion_.gravity * (h * h);
  const Vec3 joint_next = joint_ + motion_.retention * (joint_ - joint_previous_) + gravity_step;
  const Vec3 leaf_next = leaf_ + motion_.retention * (leaf_ - leaf_previous_) + gravity_step;
  joint_previous_ = joint_;
  leaf_previous_ = leaf_;
  joint_ = joint_next;
  leaf_ = leaf_next;
  for (int pass = 0; pass < motion_.iterations; ++pass)
  {
    // The root's share of the upper link's correction is dropped: the seed resets its root every frame.
    joint_ -= linkCorrection(root, joint_, upper_length_, motion_.tension);
    const Vec3 lower = linkCorrection(joint_, leaf_, lower_length_, motion_.tension);
    joint_ += lower;
    leaf_ -= lower;
  }
}

std::vector<Vec3> limbCurve(const State& state, int root_node, int samples)
{
  return sampleQuadraticBezier(state.position.col(root_node + kLimbRoot), state.position.col(root_node + kLimbJoint),
                               state.position.col(root_node + kLimbLeaf), samples);
}

void checkLimbMotion(const LimbMotion& motion, const std::string& what)
{
  const auto check = [&what](bool ok, const char* key, const std::string& reason) {
    requireDefinition(ok, what, { key }, key + (" " + reason));
  };
  check(motion.gravity.allFinite(), "gravity", "must be finite");
  check(motion.frame_period > 0.0, "frame_period", "must be > 0");
  check(motion.max_frames_per_step > 0.0 && motion.max_frames_per_step <= kMaxUpdatesPerStep, "max_frames_per_step",
        "must be in (0, " + std::to_string(kMaxUpdatesPerStep) + "]");
  check(motion.iterations >= 1 && motion.iterations <= kMaxRelaxationPasses, "iterations",
        "must be in [1, " + std::to_string(kMaxRelaxationPasses) + "]");
  // A link between two free ends changes its error by the factor 1 - 2 tension per pass: it converges
  // for 0 < tension < 1 (at 1 it flips sign forever).
  check(motion.tension > 0.0 && motion.tension < 1.0, "tension",
        "must be in (0, 1) (a free link's error changes by 1 - 2 tension per pass)");
  check(motion.retention >= 0.0 && motion.retention <= 1.0, "retention", "must be in [0, 1]");
  // Every published marker carries the curve: a few dozen points draw it smoothly.
  check(motion.curve_samples >= 2 && motion.curve_samples <= kMaxCurveSamples, "curve_samples",
        "must be in [2, " + std::to_string(kMaxCurveSamples) + "]");
}

BodyDef buildLimb(const std::string& name, const LimbDef& def)
{
  const std::string what = "limb '" + name + "'";
  checkLimbMotion(def.motion, what);
  requireDefinition(def.upper_length > 0.0, what, { "upper_length" }, "upper_length must be > 0");
  requireDefinition(def.lower_length > 0.0, what, { "lower_length" }, "lower_length must be > 0");
  requireDefinition(def.direction.norm() > 1e-12, what, { "direction" }, "direction must not be zero");
  const Vec3 along = def.direction.normalized();
  const Vec3 joint = def.root + def.upper_length * along;
  const Vec3 leaf = joint + def.lower_length * along;

  BodyDef body;
  body.name = name;
  body.type = "limb";
  // All three are pinned: the scene (or an anchor) places the root, the controller the other two; their
  // mass is only reported.
  for (const Vec3& point : { def.root, joint, leaf })
    body.nodes.push_back(NodeDef{ point, 0.01, Vec3::Zero(), true });
  body.controller = [def, joint, leaf](int first_node) {
    return std::make_unique<LimbController>(def, first_node, joint, leaf);
  };
  return body;
}

}  // namespace soft_body_sim
