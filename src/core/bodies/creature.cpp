#include "soft_body_sim/core/bodies/creature.h"

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <Eigen/Geometry>  // cross products

#include "core/bodies/fixed_period_clock.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
Vec3 softUnilateralCorrection(const Vec3& d, const SoftLength& length, double soft_strength, double hard_strength)
{
  const double l = d.norm();
  if (!(l > 1e-12))
    return Vec3::Zero();
  if (l < length.min)
    return d * ((l - length.min) / l * hard_strength);
  if (l > length.max)
    return d * ((l - length.max) / l * hard_strength);
  return d * ((l - length.relaxed) / l * soft_strength);
}

namespace
{
constexpr int kPoints = kCreatureBodyPoints;
using Points = std::array<Vec3, kPoints>;

bool isFraction(double value) { return value >= 0.0 && value <= 1.0; }

/// The start layout: the lead at `position`, the orientation point one spine length behind it, the side
/// points half a width to either side of the spine's midpoint, all in the swimming plane.
Points startPoints(const CreatureDef& def)
{
  const Vec3 normal = def.plane_normal.normalized();
  const Vec3 forward = (def.heading - normal * normal.dot(def.heading)).normalized();
  const Vec3 left = normal.cross(forward);
  const Vec3 middle = def.position - 0.5 * def.length * forward;
  Points points;
  points[kCreatureLead] = def.position;
  points[kCreatureOrientation] = def.position - def.length * forward;
  points[kCreatureLeftSide] = middle + 0.5 * def.width * left;
  points[kCreatureRightSide] = middle - 0.5 * def.width * left;
  return points;
}

SoftLength softLength(double relaxed, const CreatureDef& def)
{
  return SoftLength{ def.min_ratio * relaxed, relaxed, def.max_ratio * relaxed };
}

class CreatureController final : public Controller
{
public:
  std::unique_ptr<Controller> clone() const override { return std::make_unique<CreatureController>(*this); }
  void carry(StateArchive& archive) override
  {
    archive(clock_, x_, x_previous_, drawn_from_, target_, anticipate_);
  }
  CreatureController(const CreatureDef& def, int first_node)
    : def_(def)
    , first_node_(first_node)
    , clock_(def.update_period)
    , normal_(def.plane_normal.normalized())
    , origin_(def.position)
    , spine_(softLength(def.length, def))
    , side_to_end_(softLength(std::hypot(0.5 * def.length, 0.5 * def.width), def))
    , side_to_side_(softLength(def.width, def))
  {
    x_ = startPoints(def);
    x_previous_ = x_;
    drawn_from_ = x_;
    target_ = toPlane(def.target.value_or(def.position));
  }

  /// Keeps the dynamics one update ahead of the world's time t and draws the points on the straight line
  /// between the updates around t: at t = n T they are exactly at update n, and their velocity is the
  /// slope of that line, so attached springs feel a continuous motion.
  void step(double dt, State& state) override
  {
    clock_.run(dt, [&] { drawn_from_ = x_; }, [&] { update(); });
    for (int i = 0; i < kPoints; ++i)
      drawBetween(state, first_node_ + i, drawn_from_[i], x_[i], clock_.phase(), clock_.period());
  }

  bool takesTarget() const override { return true; }

  /// A new target (projected into the swimming plane) steers the lead from the next update on. It starts
  /// a move with anticipation only if the lead had settled on the previous target and the new one lies
  /// farther than the settle distance from it (creature.h: streamed targets); the same target again does
  /// nothing (a topic may repeat it).
  bool setTarget(const Vec3& target) override
  {
    const Vec3 in_plane = toPlane(target);
    if (in_plane == target_)
      return true;
    const double settle = def_.settle_tolerance * def_.length;
    const Vec3& lead = x_[kCreatureLead];
    const bool settled = (lead - target_).norm() <= settle && (lead - x_previous_[kCreatureLead]).norm() <= settle;
    if (settled && (in_plane - target_).norm() > settle)
      anticipate_ = true;
    target_ = in_plane;
    return true;
  }

  /// The target as the lead steers to it: in the swimming plane.
  std::optional<Vec3> target() const override { return target_; }

  /// The body outline: lead, left side, orientation point, right side, lead.
  std::vector<std::vector<Vec3>> curves(const State& state) const override
  {
    const auto at = [&](int i) { return Vec3(state.position.col(first_node_ + i)); };
    return { { at(kCreatureLead), at(kCreatureLeftSide), at(kCreatureOrientation), at(kCreatureRightSide),
               at(kCreatureLead) } };
  }

private:
  Vec3 toPlane(const Vec3& p) const { return p - normal_ * normal_.dot(p - origin_); }

  /// One update of period T, in the seed's order: antic, lead, orientation point, side points, constraints.
  void update()
  {
    const double h = def_.update_period;
    Vec3& lead = x_[kCreatureLead];
    // Anticipation: shift the lead away from the new target by a fraction of the distance. The seed's
    // pseudo-code multiplies (lead - target) by -0.2, which would shift it toward the target; its text
    // and demo move away ("moving our object ... away from the target position"), as done here. The shift
    // moves the position but not the previous one, so Verlet turns it into a velocity away from the target.
    if (anticipate_)
    {
      lead += def_.anticipation * (lead - target_);
      anticipate_ = false;
    }
    // Lead: Jakobsen Verlet with drag, x' = (1 + r) x - r x_prev + a h^2 with a = -k (x - target)
    // (the seed's 1.7 x - 0.7 x_prev + F dt^2 for r = 0.7).
    const Vec3 lead_next =
        lead + def_.lead_retention * (lead - x_previous_[kCreatureLead]) + (def_.stiffness * h * h) * (target_ - lead);
    x_previous_[kCreatureLead] = lead;
    lead = lead_next;

    // Orientation point: its velocity (per update) split along and across the spine d = lead - orientation,
    //   v_par = d (v . d) / |d|^2,  v_perp = v - v_par,  x' = x + r_par v_par + r_perp v_perp.
    Vec3& tail = x_[kCreatureOrientation];
    const Vec3 velocity = tail - x_previous_[kCreatureOrientation];
    const Vec3 spine = lead - tail;
    const double spine_squared = spine.squaredNorm();
    const Vec3 parallel = spine_squared > 1e-24 ? Vec3(spine * (velocity.dot(spine) / spine_squared)) : Vec3::Zero();
    x_previous_[kCreatureOrientation] = tail;
    tail += def_.parallel_retention * parallel + def_.perpendicular_retention * (velocity - parallel);

    // Side points: Verlet with drag and no force, x' = x + r_side (x - x_prev).
    for (const int side : { kCreatureLeftSide, kCreatureRightSide })
    {
      const Vec3 side_next = x_[side] + def_.side_retention * (x_[side] - x_previous_[side]);
      x_previous_[side] = x_[side];
      x_[side] = side_next;
    }

    // One pass of soft unilateral constraints: the spine moves only the orientation point, the four
    // side-to-end constraints only the side point, and the side-to-side one both side points by halves.
    const double soft = def_.soft_strength;
    const double hard = def_.hard_strength;
    for (int pass = 0; pass < def_.iterations; ++pass)
    {
      tail += softUnilateralCorrection(lead - tail, spine_, soft, hard);
      for (const int side : { kCreatureLeftSide, kCreatureRightSide })
      {
        x_[side] += softUnilateralCorrection(lead - x_[side], side_to_end_, soft, hard);
        x_[side] += softUnilateralCorrection(tail - x_[side], side_to_end_, soft, hard);
      }
      const Vec3 across =
          softUnilateralCorrection(x_[kCreatureRightSide] - x_[kCreatureLeftSide], side_to_side_, soft, hard);
      x_[kCreatureLeftSide] += 0.5 * across;
      x_[kCreatureRightSide] -= 0.5 * across;
    }

    // Every step above keeps the points in the plane; this only removes the round-off drift out of it.
    for (Vec3& p : x_)
      p = toPlane(p);
  }

  CreatureDef def_;
  int first_node_;
  FixedPeriodClock clock_;
  Vec3 normal_;  ///< unit normal of the swimming plane
  Vec3 origin_;  ///< a point of the swimming plane [m]
  SoftLength spine_;
  SoftLength side_to_end_;   ///< side point to lead and to orientation point
  SoftLength side_to_side_;
  Points x_;           ///< the points at the next update instant [m]
  Points x_previous_;  ///< Verlet history: the points one update earlier (after an antic shift: before it)
  Points drawn_from_;  ///< the points at the last update instant passed [m]
  Vec3 target_;
  bool anticipate_ = false;
};

/// Appends a tendril hanging from body point `side`: a rope from the side point along `direction`, whose
/// first node is the side point itself.
void addTendril(BodyDef& body, int side, const TendrilDef& tendril)
{
  RopeDef rope;
  rope.nodes = tendril.segments + 1;
  rope.from = body.nodes[static_cast<std::size_t>(side)].position;
  rope.to = rope.from + tendril.length * tendril.direction.normalized();
  rope.mass = tendril.mass / tendril.segments * rope.nodes;  // buildRope spreads it over all nodes
  rope.stiffness = tendril.stiffness;
  rope.damping = tendril.damping;
  const BodyDef strand = buildRope("tendril", rope);
  const int first = static_cast<int>(body.nodes.size()) - 1;  // strand node k > 0 becomes first + k
  body.nodes.insert(body.nodes.end(), strand.nodes.begin() + 1, strand.nodes.end());
  for (SpringDef spring : strand.springs)
  {
    spring.a = spring.a == 0 ? side : first + spring.a;
    spring.b = spring.b == 0 ? side : first + spring.b;
    body.springs.push_back(spring);
  }
}

}  // namespace

BodyDef buildCreature(const std::string& name, const CreatureDef& def)
{
  const std::string what = "creature '" + name + "'";
  const auto check = [&what](bool ok, std::vector<std::string> keys, const std::string& reason) {
    requireDefinition(ok, what, std::move(keys), reason);
  };
  check(def.length > 0.0, { "length" }, "length must be > 0");
  check(def.width > 0.0, { "width" }, "width must be > 0");
  check(def.update_period > 0.0, { "update_period" }, "update_period must be > 0");
  check(def.stiffness >= 0.0, { "stiffness" }, "stiffness must be >= 0");
  for (const auto& [key, value] : { std::pair{ "lead_retention", def.lead_retention },
                                    std::pair{ "parallel_retention", def.parallel_retention },
                                    std::pair{ "perpendicular_retention", def.perpendicular_retention },
                                    std::pair{ "side_retention", def.side_retention } })
    check(isFraction(value), { key }, std::string(key) + " must be in [0, 1]");
  // The lead's recurrence z^2 - (1 + r - k T^2) z + r = 0 has both roots inside the unit circle iff
  // r < 1 and 0 < k T^2 < 2 (1 + r) (Jury's test); k = 0 or r = 1 is marginal (no spring / no drag).
  const double k_t2 = def.stiffness * def.update_period * def.update_period;
  check(k_t2 < 2.0 * (1.0 + def.lead_retention), { "stiffness", "update_period", "lead_retention" },
        "stiffness * update_period^2 = " + formatNumber(k_t2) + " must be < 2 (1 + lead_retention) = " +
            formatNumber(2.0 * (1.0 + def.lead_retention)) + " for the lead's recurrence to be stable");
  check(def.anticipation >= 0.0, { "anticipation" }, "anticipation must be >= 0");
  check(def.settle_tolerance > 0.0, { "settle_tolerance" }, "settle_tolerance must be > 0");
  check(def.iterations >= 1 && def.iterations <= kMaxRelaxationPasses, { "iterations" },
        "iterations must be in [1, " + std::to_string(kMaxRelaxationPasses) + "]");
  check(def.min_ratio > 0.0 && def.min_ratio <= 1.0, { "min_ratio" }, "min_ratio must be in (0, 1]");
  check(def.max_ratio >= 1.0, { "max_ratio" }, "max_ratio must be >= 1");
  check(def.soft_strength > 0.0 && def.soft_strength <= 1.0, { "soft_strength" }, "soft_strength must be in (0, 1]");
  check(def.hard_strength > 0.0 && def.hard_strength <= 1.0, { "hard_strength" }, "hard_strength must be in (0, 1]");
  check(def.plane_normal.norm() > 1e-12, { "plane_normal" }, "plane_normal must not be zero");
  check(def.heading.norm() > 1e-12, { "heading" }, "heading must not be zero");
  const Vec3 normal = def.plane_normal.normalized();
  check((def.heading - normal * normal.dot(def.heading)).norm() > 1e-9 * def.heading.norm(),
        { "heading", "plane_normal" },
        "heading must not be parallel to plane_normal (the spine lies in the swimming plane)");
  if (def.tendrils)
  {
    const TendrilDef& t = *def.tendrils;
    check(t.segments >= 1 && t.segments <= kMaxSceneNodes / 2, { "tendrils.segments" },  // two tendrils
          "tendrils.segments must be in [1, " + std::to_string(kMaxSceneNodes / 2) + "]");
    for (const auto& [key, value] : { std::pair{ "length", t.length }, std::pair{ "mass", t.mass },
                                      std::pair{ "stiffness", t.stiffness } })
      check(value > 0.0, { std::string("tendrils.") + key }, std::string("tendrils.") + key + " must be > 0");
    check(t.damping >= 0.0, { "tendrils.damping" }, "tendrils.damping must be >= 0");
    check(t.direction.norm() > 1e-12, { "tendrils.direction" }, "tendrils.direction must not be zero");
  }

  BodyDef body;
  body.name = name;
  body.type = "creature";
  // The body points are pinned: the controller moves them, and their mass is only reported.
  for (const Vec3& point : startPoints(def))
    body.nodes.push_back(NodeDef{ point, 0.01, Vec3::Zero(), true });
  if (def.tendrils)
  {
    addTendril(body, kCreatureLeftSide, *def.tendrils);
    addTendril(body, kCreatureRightSide, *def.tendrils);
  }
  body.controller = [def](int first_node) { return std::make_unique<CreatureController>(def, first_node); };
  return body;
}

}  // namespace soft_body_sim
