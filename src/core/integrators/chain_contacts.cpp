#include "core/integrators/chain_contacts.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace soft_body_sim
{
namespace
{
/// A node this close to a surface [m] beyond its contact radius is still on it: a node sliding over a
/// curved surface leaves its tangent plane by s^2 / 2R in a sub-step that moves it by s (40 um for 2 mm
/// over a 5 cm radius), and a node resting on it by round-off. A quarter of the contact radius, plus 1 um
/// for point nodes.
double holdMargin(const Model& model, int node) { return 0.25 * model.contact_radius[node] + 1e-6; }

/// The part of v in the plane normal to the unit vector n.
Vec3 tangential(const Vec3& v, const Vec3& n) { return v - v.dot(n) * n; }

/// v / |v|, or zero.
Vec3 unit(const Vec3& v)
{
  const double length = v.norm();
  return length > 1e-300 ? Vec3(v / length) : Vec3::Zero();
}
}  // namespace

void ChainContacts::setPaths(const Model& model, std::vector<ChainPath> paths)
{
  paths_ = std::move(paths);
  const int nodes = model.nodeCount();
  std::vector<char> listed(static_cast<std::size_t>(nodes), 0);
  nodes_.clear();
  for (const ChainPath& path : paths_)
    for (const int node : path.nodes)
      if (model.isFree(node) && !listed[static_cast<std::size_t>(node)])
      {
        listed[static_cast<std::size_t>(node)] = 1;
        nodes_.push_back(node);
      }
  // The arrays are per node of the model, for the solve's node indices; a scene without chains (a cloth)
  // holds none of them (about 250 bytes a node).
  const Eigen::Index count = paths_.empty() ? 0 : nodes;
  holds_.kind.assign(static_cast<std::size_t>(count), NodeHolds::kFree);
  holds_.normal.setZero(3, count);
  holds_.push.setZero(3, count);
  holds_.slip.setZero(3, count);
  holds_.friction.assign(static_cast<std::size_t>(count), 0.0);
  before_.assign(static_cast<std::size_t>(count), NodeHolds::kFree);
  predicted_.setZero(3, count);
  contact_.assign(static_cast<std::size_t>(count), NodeContact{ Vec3::UnitZ(), Vec3::Zero(), 0.0, 0.0 });
  slip_.setZero(3, count);
  impulse_.setZero(3, count);
  pressed_.clear();
  pressed_.reserve(nodes_.size());  // no allocation in a sub-step
  force_.setZero(3, count);
}

Vec3 ChainContacts::along(const ChainPath& path, std::size_t j, const NodeArray& x) const
{
  const int node = path.nodes[j];
  const Vec3 chord = x.col(path.nodes[std::min(j + 1, path.nodes.size() - 1)]) - x.col(path.nodes[j > 0 ? j - 1 : 0]);
  return unit(tangential(chord, holds_.normal.col(node)));
}

void ChainContacts::setSlip(const ChainPath& path, std::size_t first, std::size_t end, const NodeArray& x,
                            double towards_end)
{
  const double sign = towards_end >= 0.0 ? 1.0 : -1.0;
  for (std::size_t j = first; j < end; ++j)
    slip_.col(path.nodes[j]) = sign * along(path, j, x);
}

template <typename Visit>
void ChainContacts::forEachRun(Visit visit) const
{
  for (const ChainPath& path : paths_)
  {
    std::size_t j = 0;
    while (j < path.nodes.size())
    {
      if (holds_.kind[static_cast<std::size_t>(path.nodes[j])] == NodeHolds::kFree)
      {
        ++j;
        continue;
      }
      std::size_t end = j;
      while (end < path.nodes.size() && holds_.kind[static_cast<std::size_t>(path.nodes[end])] != NodeHolds::kFree)
        ++end;
      visit(path, j, end);
      j = end;
    }
  }
}

bool ChainContacts::hold(const Model& model, const ContactQuery& contacts, const NodeArray& start, double h,
                         NodeArray& x)
{
  bool any = false;
  for (const int i : nodes_)
  {
    const std::size_t k = static_cast<std::size_t>(i);
    before_[k] = holds_.kind[k];
    predicted_.col(i) = x.col(i);
    NodeContact& contact = contact_[k];
    // A new contact needs the prediction inside the contact radius; a held node stays held within the
    // margin (a node just pulled off a surface is not caught again by it).
    const double margin = before_[k] == NodeHolds::kFree ? 0.0 : holdMargin(model, i);
    if (!contacts.touching(model, i, x.col(i), margin, contact))
    {
      holds_.kind[k] = NodeHolds::kFree;
      continue;
    }
    any = true;
    holds_.kind[k] = NodeHolds::kStick;  // for now: marks it held (the run decides below)
    holds_.normal.col(i) = contact.normal;
  }
  if (!any)
    return false;
  // A run slides if any of its nodes slid at the last sub-step, sticks if any stuck, and a new one
  // sticks if it can (the check after the solve says whether it holds).
  forEachRun([&](const ChainPath& path, std::size_t first, std::size_t end) {
    bool slid = false, stuck = false, frictionless = true;
    for (std::size_t j = first; j < end; ++j)
    {
      const std::size_t k = static_cast<std::size_t>(path.nodes[j]);
      slid = slid || before_[k] == NodeHolds::kSlide;
      stuck = stuck || before_[k] == NodeHolds::kStick;
      frictionless = frictionless && !(contact_[k].friction > 0.0);
    }
    const std::uint8_t kind = slid || (!stuck && frictionless) ? NodeHolds::kSlide : NodeHolds::kStick;
    // A sliding run slips along itself the way it is moving relative to the surface, or on as before.
    double moving = 0.0, before = 0.0;
    for (std::size_t j = first; j < end; ++j)
    {
      const int i = path.nodes[j];
      const std::size_t k = static_cast<std::size_t>(i);
      holds_.kind[k] = kind;
      const Vec3 forward = along(path, j, x);
      moving += (predicted_.col(i) - start.col(i) - h * contact_[k].velocity).dot(forward);
      before += slip_.col(i).dot(forward);
    }
    setSlip(path, first, end, x, moving != 0.0 ? moving : before);
  });
  place(model, start, h, x);
  return true;
}

void ChainContacts::place(const Model& model, const NodeArray& start, double h, NodeArray& x)
{
  for (const int i : nodes_)
  {
    const std::size_t k = static_cast<std::size_t>(i);
    const NodeContact& contact = contact_[k];
    holds_.slip.col(i) = slip_.col(i);
    holds_.friction[k] = contact.friction;
    holds_.push.col(i) = (-contact.friction * contact.depth / model.inverse_mass[i]) * slip_.col(i);
    switch (holds_.kind[k])
    {
      case NodeHolds::kFree:
        x.col(i) = predicted_.col(i);
        break;
      case NodeHolds::kStick:
      {
        // Where the surface takes it, on the surface (its depth there from the prediction's, the surface
        // taken as its tangent plane over the sub-step's motion).
        const Vec3 carried = start.col(i) + h * contact.velocity;
        const double depth = contact.depth + (predicted_.col(i) - carried).dot(contact.normal);
        x.col(i) = carried + depth * contact.normal;
        break;
      }
      case NodeHolds::kSlide:
        x.col(i) = predicted_.col(i) + contact.depth * contact.normal;
        break;
    }
  }
}

bool ChainContacts::check(const Model& model, const std::vector<SweepRow>& rows, double* lambda,
                          const NodeArray& start, double h, const NodeArray& x)
{
  const double h2 = h * h;
  // The tensions [N] of the rows just outside the run nodes[first, end) of `path`, where it has them.
  const auto ends = [&](const ChainPath& path, std::size_t first, std::size_t end) {
    std::pair<std::optional<double>, std::optional<double>> tensions;
    if (first > 0)
      tensions.first = -lambda[path.rows[first - 1]] / h2;
    if (end < path.nodes.size())
      tensions.second = -lambda[path.rows[end - 1]] / h2;
    return tensions;
  };
  // Inside a stuck run, the tensions change geometrically from one end's to the other's (linearly if
  // either is slack); a run with a single end takes its tension throughout.
  forEachRun([&](const ChainPath& path, std::size_t first, std::size_t end) {
    if (holds_.kind[static_cast<std::size_t>(path.nodes[first])] != NodeHolds::kStick)
      return;
    const auto [before, after] = ends(path, first, end);
    if (!before && !after)
      return;
    const double t0 = before.value_or(*after), t1 = after.value_or(*before);
    // Each node's share of the change is its bend (the angle between its two rows), as the capstan's
    // dT / T = mu dtheta: at the run's ends, where the rope meets the surface, a node bends it half as
    // much as inside. A straight run shares it evenly.
    const auto bend = [&](std::size_t j) {
      if (j == 0 || j + 1 == path.nodes.size())
        return 0.0;
      const Vec3 in = x.col(path.nodes[j]) - x.col(path.nodes[j - 1]);
      const Vec3 out = x.col(path.nodes[j + 1]) - x.col(path.nodes[j]);
      return std::atan2(in.cross(out).norm(), in.dot(out));
    };
    double total = 0.0;
    for (std::size_t j = first; j < end; ++j)
      total += bend(j);
    const bool even = !(total > 1e-9);
    double sum = 0.0;
    for (std::size_t e = first; e + 1 < end; ++e)
    {
      sum += even ? 1.0 : bend(e);
      const double s = sum / (even ? static_cast<double>(end - first) : total);
      const double t = t0 > 1e-12 && t1 > 1e-12 ? t0 * std::pow(t1 / t0, s) : t0 + s * (t1 - t0);
      lambda[path.rows[e]] = -t * h2;
    }
  });
  for (const int i : nodes_)
    impulse_.col(i).setZero();
  for (std::size_t r = 0; r < rows.size(); ++r)
  {
    const Vec3 d = x.col(rows[r].a) - x.col(rows[r].b);
    const double length = d.norm();
    if (length < kMinSpringLength)
      continue;
    const Vec3 push = (lambda[r] / length) * d;
    impulse_.col(rows[r].a) += push;
    impulse_.col(rows[r].b) -= push;
  }
  bool changed = false;
  pressed_.clear();
  forEachRun([&](const ChainPath& path, std::size_t first, std::size_t end) {
    const bool stuck = holds_.kind[static_cast<std::size_t>(path.nodes[first])] == NodeHolds::kStick;
    bool lifts = false, exceeds = false;
    double slipped = 0.0, friction = 0.0;
    for (std::size_t j = first; j < end; ++j)
    {
      const int i = path.nodes[j];
      const std::size_t k = static_cast<std::size_t>(i);
      const NodeContact& contact = contact_[k];
      const Vec3 force = ((x.col(i) - predicted_.col(i)) / model.inverse_mass[i] - impulse_.col(i)) / h2;
      force_.col(i) = force;
      pressed_.push_back(i);
      const double pressing = force.dot(contact.normal);
      if (!(pressing > 0.0))
      {
        holds_.kind[k] = NodeHolds::kFree;  // the surface would have to pull it: it leaves
        lifts = true;
        continue;
      }
      exceeds = exceeds || tangential(force, contact.normal).norm() > contact.friction * pressing * (1.0 + 1e-9);
      slipped += tangential(x.col(i) - start.col(i) - h * contact.velocity, contact.normal).dot(slip_.col(i));
      friction = std::max(friction, contact.friction);
    }
    if (lifts)
    {
      changed = true;
      return;
    }
    const bool enclosed = first > 0 && end < path.nodes.size() && immobile(model, path.nodes[first - 1]) &&
                          immobile(model, path.nodes[end]);
    if (stuck && exceeds && !enclosed)
    {
      // It slides towards its more tense end.
      const auto [before, after] = ends(path, first, end);
      for (std::size_t j = first; j < end; ++j)
        holds_.kind[static_cast<std::size_t>(path.nodes[j])] = NodeHolds::kSlide;
      setSlip(path, first, end, x, after.value_or(0.0) - before.value_or(0.0));
      changed = true;
    }
    else if (!stuck && friction > 0.0 && slipped < 0.0)
    {
      for (std::size_t j = first; j < end; ++j)
        holds_.kind[static_cast<std::size_t>(path.nodes[j])] = NodeHolds::kStick;  // friction turned it back
      changed = true;
    }
  });
  return changed;
}

void ChainContacts::report(const Model& model, double h, const NodeArray& x, ContactQuery& contacts) const
{
  for (const int i : pressed_)
  {
    const NodeContact& contact = contact_[static_cast<std::size_t>(i)];
    contacts.receive(contact, x.col(i) - model.contact_radius[i] * contact.normal, -h * force_.col(i));
  }
}

}  // namespace soft_body_sim
