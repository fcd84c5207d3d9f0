#include "soft_body_sim/ros/ros_converter.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "soft_body_sim/core/elements/rods.h"

namespace soft_body_sim
{
namespace
{
constexpr double kNodeDiameter = 0.02;  // [m] sphere size in rviz
constexpr double kLineWidth = 0.005;    // [m]

/// A distinct, stable colour per body index (golden-angle hues).
std_msgs::ColorRGBA bodyColor(std::size_t body)
{
  const double hue = std::fmod(static_cast<double>(body) * 137.508, 360.0) / 60.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  const double rgb[6][3] = { { 1, x, 0 }, { x, 1, 0 }, { 0, 1, x }, { 0, x, 1 }, { x, 0, 1 }, { 1, 0, x } };
  const auto& c = rgb[static_cast<int>(hue) % 6];
  std_msgs::ColorRGBA color;
  color.r = static_cast<float>(0.2 + 0.8 * c[0]);
  color.g = static_cast<float>(0.2 + 0.8 * c[1]);
  color.b = static_cast<float>(0.2 + 0.8 * c[2]);
  color.a = 1.0f;
  return color;
}

visualization_msgs::Marker marker(const std::string& frame_id, const ros::Time& stamp, const std::string& ns, int id,
                                  int type, double scale, const std_msgs::ColorRGBA& color)
{
  visualization_msgs::Marker m;
  m.header.frame_id = frame_id;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = scale;
  m.color = color;
  return m;
}

geometry_msgs::Point point(const Vec3& p)
{
  geometry_msgs::Point out;
  out.x = p.x();
  out.y = p.y();
  out.z = p.z();
  return out;
}

/// A grey solid for the colliders, a little transparent so that a body behind one stays visible.
std_msgs::ColorRGBA colliderColor()
{
  std_msgs::ColorRGBA color;
  color.r = color.g = color.b = 0.6f;
  color.a = 0.8f;
  return color;
}

geometry_msgs::Pose pose(const Vec3& position, const Eigen::Quaterniond& orientation)
{
  geometry_msgs::Pose out;
  out.position = point(position);
  out.orientation.x = orientation.x();
  out.orientation.y = orientation.y();
  out.orientation.z = orientation.z();
  out.orientation.w = orientation.w();
  return out;
}

/// Namespace "colliders": per collider k, id 3k its solid (SPHERE, CYLINDER, CUBE, or a MESH_RESOURCE of
/// the mesh's file at its scale, in its pose); a capsule adds its two end caps as SPHEREs, ids 3k + 1 and
/// 3k + 2.
void addColliderMarkers(const World& world, const std::string& frame_id, const ros::Time& stamp,
                        visualization_msgs::MarkerArray& array)
{
  const std::vector<ColliderPose> poses = world.colliderPoses();
  for (std::size_t k = 0; k < poses.size(); ++k)
  {
    const ColliderPose& c = poses[k];
    const int id = 3 * static_cast<int>(k);
    int type = visualization_msgs::Marker::SPHERE;
    if (c.shape == ColliderPose::Shape::Capsule || c.shape == ColliderPose::Shape::Cylinder)
      type = visualization_msgs::Marker::CYLINDER;
    else if (c.shape == ColliderPose::Shape::Box)
      type = visualization_msgs::Marker::CUBE;
    else if (c.shape == ColliderPose::Shape::Mesh)
      type = visualization_msgs::Marker::MESH_RESOURCE;
    visualization_msgs::Marker solid = marker(frame_id, stamp, "colliders", id, type, 1.0, colliderColor());
    if (c.shape == ColliderPose::Shape::Mesh)
    {
      solid.mesh_resource = c.mesh;
      solid.mesh_use_embedded_materials = false;  // the colliders' grey, as the other shapes
    }
    solid.pose = pose(c.position, c.orientation);
    solid.scale.x = c.size.x();
    solid.scale.y = c.size.y();
    solid.scale.z = c.size.z();
    array.markers.push_back(solid);
    if (c.shape != ColliderPose::Shape::Capsule)
      continue;
    for (const int end : { 1, 2 })
    {
      const Vec3 axis = c.orientation * Vec3(0.0, 0.0, (end == 1 ? 0.5 : -0.5) * c.size.z());
      visualization_msgs::Marker cap = marker(frame_id, stamp, "colliders", id + end,
                                              visualization_msgs::Marker::SPHERE, c.size.x(), colliderColor());
      cap.pose = pose(c.position + axis, c.orientation);
      array.markers.push_back(cap);
    }
  }
}

/// A line from node a to node b if both ends are finite.
void addSegment(const NodeArray& x, int a, int b, visualization_msgs::Marker& lines)
{
  if (!x.col(a).allFinite() || !x.col(b).allFinite())
    return;
  lines.points.push_back(point(x.col(a)));
  lines.points.push_back(point(x.col(b)));
}

geometry_msgs::Vector3 vector3(const Vec3& v)
{
  geometry_msgs::Vector3 out;
  out.x = v.x();
  out.y = v.y();
  out.z = v.z();
  return out;
}

}  // namespace

namespace
{
/// Each rod as a LINE_STRIP of its diameter (id 2 in its body's namespace) and, in the namespace
/// "<body>/frames" (which rviz can hide on its own), each segment's material frame as three short lines
/// from its midpoint, red x along the rod, green y, blue z: a twist shows as the green and blue lines
/// turning about the rod.
void addRodMarkers(const World& world, const std::string& frame_id, const ros::Time& stamp,
                   visualization_msgs::MarkerArray& array)
{
  const Model& model = world.model();
  const NodeArray& x = world.state().position;
  std::vector<Eigen::Quaterniond> frames;
  for (std::size_t r = 0; r < model.rods.size(); ++r)
  {
    const Rod& rod = model.rods[r];
    const std::size_t b = model.bodyOf(rod.first);
    const std::string& name = model.bodies[b].name;
    visualization_msgs::Marker strip = marker(frame_id, stamp, name, 2, visualization_msgs::Marker::LINE_STRIP,
                                              2.0 * model.contact_radius[rod.first], bodyColor(b));
    visualization_msgs::Marker axes =
        marker(frame_id, stamp, name + "/frames", 0, visualization_msgs::Marker::LINE_LIST, 0.5 * kLineWidth, bodyColor(b));
    rodFrames(rod, x, world.state().twist, frames);
    const double length = 0.8 * rod.segment_length;
    for (int j = 0; j < rod.count; ++j)
    {
      const Vec3 p = x.col(rod.first + j);
      if (!p.allFinite())
        continue;
      strip.points.push_back(point(p));
      if (j + 1 == rod.count || !x.col(rod.first + j + 1).allFinite())
        continue;
      const Vec3 middle = 0.5 * (p + x.col(rod.first + j + 1));
      const Eigen::Matrix3d axis = frames[static_cast<std::size_t>(j)].toRotationMatrix();
      for (int c = 0; c < 3; ++c)
      {
        std_msgs::ColorRGBA color;
        color.r = c == 0 ? 1.0f : 0.0f;
        color.g = c == 1 ? 1.0f : 0.0f;
        color.b = c == 2 ? 1.0f : 0.0f;
        color.a = 1.0f;
        axes.points.push_back(point(middle));
        axes.points.push_back(point(middle + length * axis.col(c)));
        axes.colors.push_back(color);
        axes.colors.push_back(color);
      }
    }
    for (visualization_msgs::Marker* m : { &strip, &axes })
    {
      if (m->points.empty())
        m->action = visualization_msgs::Marker::DELETE;
      array.markers.push_back(*m);
    }
  }
}
}  // namespace

namespace
{
/// Each solid's boundary (BodyRange::surface) as a TRIANGLE_LIST in its body's colour (id 2 in its body's
/// namespace): rviz shades each triangle by its normal, (b - a) x (c - a), which points out of the solid.
/// A triangle with a node that is not finite is left out.
void addVolumeMarkers(const World& world, const std::string& frame_id, const ros::Time& stamp,
                      visualization_msgs::MarkerArray& array)
{
  const Model& model = world.model();
  const NodeArray& x = world.state().position;
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    if (body.surface.empty())
      continue;
    visualization_msgs::Marker triangles =
        marker(frame_id, stamp, body.name, 2, visualization_msgs::Marker::TRIANGLE_LIST, 1.0, bodyColor(b));
    for (const std::array<int, 3>& t : body.surface)
      if (x.col(t[0]).allFinite() && x.col(t[1]).allFinite() && x.col(t[2]).allFinite())
        for (const int node : t)
          triangles.points.push_back(point(x.col(node)));
    if (triangles.points.empty())
      triangles.action = visualization_msgs::Marker::DELETE;
    array.markers.push_back(triangles);
  }
}
}  // namespace

visualization_msgs::MarkerArray RosConverter::toMarkers(const World& world, const std::string& frame_id,
                                                        const ros::Time& stamp)
{
  const Model& model = world.model();
  const NodeArray& x = world.state().position;
  visualization_msgs::MarkerArray array;
  std::vector<int> body_of_node(static_cast<std::size_t>(model.nodeCount()));
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    const std_msgs::ColorRGBA color = bodyColor(b);
    // A solid's nodes go in a namespace of their own, "<body>/nodes", which rviz can hide: its surface
    // (addVolumeMarkers) is the solid.
    const std::string nodes_namespace = body.surface.empty() ? body.name : body.name + "/nodes";
    visualization_msgs::Marker nodes =
        marker(frame_id, stamp, nodes_namespace, 0, visualization_msgs::Marker::SPHERE_LIST, kNodeDiameter, color);
    // A rod is drawn as itself (addRodMarkers): no node balls, no link lines.
    const bool rod = std::any_of(model.rods.begin(), model.rods.end(), [&](const Rod& r) { return r.first == body.first; });
    for (int i = body.first; i < body.first + body.count; ++i)
    {
      body_of_node[static_cast<std::size_t>(i)] = rod ? -1 : static_cast<int>(b);
      if (!rod && x.col(i).allFinite())
        nodes.points.push_back(point(x.col(i)));
    }
    array.markers.push_back(nodes);
    array.markers.push_back(
        marker(frame_id, stamp, body.name, 1, visualization_msgs::Marker::LINE_LIST, kLineWidth, color));
  }
  // Springs and constraints join nodes of one body; each goes to that body's LINE_LIST (index 2b + 1),
  // but a rod's (body_of_node -1).
  for (const Spring& s : model.springs)
    if (body_of_node[static_cast<std::size_t>(s.a)] >= 0)
      addSegment(x, s.a, s.b, array.markers[2 * static_cast<std::size_t>(body_of_node[s.a]) + 1]);
  for (const DistanceConstraint& c : model.constraints)
    if (body_of_node[static_cast<std::size_t>(c.a)] >= 0)
      addSegment(x, c.a, c.b, array.markers[2 * static_cast<std::size_t>(body_of_node[c.a]) + 1]);

  // rviz rejects list markers without points; an empty one is sent as DELETE, which also clears a
  // marker that once had points.
  for (visualization_msgs::Marker& m : array.markers)
    if (m.points.empty())
      m.action = visualization_msgs::Marker::DELETE;

  for (const BodyController& controlled : world.controllers())
  {
    const BodyRange& body = model.bodies[static_cast<std::size_t>(controlled.body)];
    int id = 2;
    for (const std::vector<Vec3>& curve : controlled.controller->curves(world.state()))
    {
      visualization_msgs::Marker strip = marker(frame_id, stamp, body.name, id++, visualization_msgs::Marker::LINE_STRIP,
                                                2.0 * kLineWidth, bodyColor(static_cast<std::size_t>(controlled.body)));
      for (const Vec3& p : curve)
        if (p.allFinite())
          strip.points.push_back(point(p));
      array.markers.push_back(strip);
    }
  }
  addRodMarkers(world, frame_id, stamp, array);
  addVolumeMarkers(world, frame_id, stamp, array);
  addColliderMarkers(world, frame_id, stamp, array);
  return array;
}

visualization_msgs::MarkerArray RosConverter::toForceMarkers(const std::vector<Holder>& holders, double force_scale,
                                                             const std::string& frame_id, const ros::Time& stamp)
{
  visualization_msgs::MarkerArray array;
  // White: no body's hue (bodyColor), and brighter than the colliders' grey.
  std_msgs::ColorRGBA white;
  white.r = white.g = white.b = white.a = 1.0f;
  array.markers.push_back(marker(frame_id, stamp, "forces", 0, visualization_msgs::Marker::ARROW, 1.0, white));
  array.markers.back().action = visualization_msgs::Marker::DELETEALL;
  for (std::size_t k = 0; k < holders.size(); ++k)
  {
    visualization_msgs::Marker arrow =
        marker(frame_id, stamp, "forces", static_cast<int>(k), visualization_msgs::Marker::ARROW, 1.0, white);
    arrow.scale.x = kLineWidth;        // shaft diameter [m]
    arrow.scale.y = 2.0 * kLineWidth;  // head diameter
    arrow.scale.z = 0.0;               // head length: rviz's default share of the arrow
    arrow.points = { point(holders[k].origin), point(holders[k].origin + force_scale * holders[k].wrench.force) };
    array.markers.push_back(arrow);
  }
  return array;
}

std::vector<Holder> RosConverter::holders(const World& world)
{
  std::vector<Holder> holders;
  const Model& model = world.model();
  const std::vector<Wrench> anchors = world.anchorWrenches();
  for (std::size_t k = 0; k < anchors.size(); ++k)
  {
    const Anchor& anchor = model.anchors[k];
    holders.push_back({ model.bodyOf(anchor.node), anchor.name, world.state().position.col(anchor.node), anchors[k] });
  }
  const std::vector<Wrench> grasps = world.graspWrenches();
  for (std::size_t k = 0; k < grasps.size(); ++k)
  {
    const GraspedNodes& grasp = world.grasps()[k];
    holders.push_back({ grasp.body, grasp.name, grasp.pose.position, grasps[k] });
  }
  return holders;
}

geometry_msgs::WrenchStamped RosConverter::toWrench(const Wrench& wrench, const std::string& frame_id,
                                                    const ros::Time& stamp)
{
  geometry_msgs::WrenchStamped out;
  out.header.frame_id = frame_id;
  out.header.stamp = stamp;
  out.wrench.force = vector3(wrench.force);
  out.wrench.torque = vector3(wrench.torque);
  return out;
}

SimState RosConverter::toState(const World& world, const std::string& frame_id, const ros::Time& stamp,
                               const StepStatistics& statistics, const std::vector<Holder>& holders,
                               const std::vector<GraspSlip>& slips)
{
  const Model& model = world.model();
  const Eigen::VectorXd tension = world.linkTensions();
  SimState state;
  state.header.frame_id = frame_id;
  state.header.stamp = stamp;
  state.real_time_factor = statistics.real_time_factor;
  state.wall_seconds_per_step = statistics.wall_seconds_per_step;
  state.divergence_events = statistics.divergence_events;
  for (std::size_t b = 0; b < world.model().bodies.size(); ++b)
  {
    const BodyRange& range = world.model().bodies[b];
    BodyState body;
    body.name = range.name;
    body.integrator = integratorName(world.bodyIntegrator(b));
    body.divergence_events = static_cast<std::uint32_t>(world.divergenceCount(b));
    body.frozen = world.isFrozen(b);
    for (int i = range.first; i < range.first + range.count; ++i)
    {
      body.positions.push_back(point(world.state().position.col(i)));
      body.velocities.push_back(vector3(world.state().velocity.col(i)));
    }
    for (const Holder& holder : holders)
      if (holder.body == b)
      {
        body.holders.push_back(holder.name);
        geometry_msgs::Wrench wrench;
        wrench.force = vector3(holder.wrench.force);
        wrench.torque = vector3(holder.wrench.torque);
        body.wrenches.push_back(wrench);
      }
    for (const GraspSlip& slip : slips)
      if (slip.body == range.name)
        body.slips.push_back(slip.describe());
    state.bodies.push_back(body);
  }
  // A link belongs to the body of its first node; buildWorld adds each body's links in order.
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    state.bodies[model.bodyOf(model.springs[k].a)].tensions.push_back(tension[static_cast<Eigen::Index>(k)]);
  for (std::size_t k = 0; k < model.constraints.size(); ++k)
    state.bodies[model.bodyOf(model.constraints[k].a)].tensions.push_back(
        tension[static_cast<Eigen::Index>(model.springs.size() + k)]);
  return state;
}

geometry_msgs::Pose RosConverter::toPose(const Vec3& position)
{
  geometry_msgs::Pose pose;
  pose.position.x = position.x();
  pose.position.y = position.y();
  pose.position.z = position.z();
  pose.orientation.w = 1.0;
  return pose;
}

bool RosConverter::fromPose(const geometry_msgs::Pose& pose, Vec3& position, std::string& why)
{
  const Vec3 p = toVec3(pose.position);
  const Eigen::Vector4d q(pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w);
  if (!p.allFinite())
  {
    why = "position is not finite";
    return false;
  }
  if (!q.allFinite())
  {
    why = "orientation is not finite";
    return false;
  }
  position = p;
  return true;
}

bool RosConverter::fromPose(const geometry_msgs::Pose& pose, Vec3& position,
                            std::optional<Eigen::Quaterniond>& orientation, std::string& why)
{
  if (!fromPose(pose, position, why))
    return false;
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  orientation.reset();
  if (q.norm() > 1e-12)
    orientation = q.normalized();
  return true;
}

std::optional<RigidPose> RosConverter::toRigidPose(const geometry_msgs::Transform& transform)
{
  RigidPose pose;
  pose.position = toVec3(transform.translation);
  pose.orientation = Eigen::Quaterniond(transform.rotation.w, transform.rotation.x, transform.rotation.y,
                                        transform.rotation.z);
  if (!pose.position.allFinite() || !pose.orientation.coeffs().allFinite() || !(pose.orientation.norm() > 1e-12))
    return std::nullopt;
  pose.orientation.normalize();
  return pose;
}

SimConfig RosConverter::toSimConfig(const World& world)
{
  SimConfig config = SimConfig::__getDefault__();
  config.integrator = integratorName(world.integrator());
  config.dt = world.settings().dt;
  config.substeps = world.settings().substeps;
  config.iterations = world.settings().iterations;
  config.gravity_x = world.model().gravity.x();
  config.gravity_y = world.model().gravity.y();
  config.gravity_z = world.model().gravity.z();
  config.drag = world.model().drag;
  return config;
}

bool RosConverter::integratorOf(const SimConfig& config, IntegratorType& integrator, std::string& why)
{
  if (integratorFromName(config.integrator, integrator))
    return true;
  // Quoted back only as far as a name could be: the request may hold megabytes.
  const std::size_t shown = 32;
  why = "integrator '" + config.integrator.substr(0, shown) + (config.integrator.size() > shown ? "...'" : "'") +
        " is unknown; valid:";
  for (const std::string& name : integratorNames())
    why += " " + name;
  return false;
}

}  // namespace soft_body_sim
