// RosConverter: the rviz markers of the bodies (nodes, links, rods, solids, controllers' curves), of the
// colliders and of the forces on the holders.
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

/// An opaque rviz colour of rgb `c` in [0, 1] (a body's Look::color).
std_msgs::ColorRGBA rvizColor(const Eigen::Vector3d& c, float alpha = 1.0f)
{
  std_msgs::ColorRGBA color;
  color.r = static_cast<float>(c.x());
  color.g = static_cast<float>(c.y());
  color.b = static_cast<float>(c.z());
  color.a = alpha;
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

/// A collider's colour, a little transparent so that a body behind one stays visible.
std_msgs::ColorRGBA colliderColor(const ColliderPose& collider)
{
  return rvizColor(collider.color, 0.8f);
}

/// Namespace "colliders": per collider k, id 3k its solid (SPHERE, CYLINDER, CUBE, or a MESH_RESOURCE of
/// the mesh's file at its scale, in its pose); a capsule adds its two end caps as SPHEREs, ids 3k + 1 and
/// 3k + 2.
void addColliderMarkers(const std::vector<ColliderPose>& poses, const std::string& frame_id, const ros::Time& stamp,
                        visualization_msgs::MarkerArray& array)
{
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
    visualization_msgs::Marker solid = marker(frame_id, stamp, "colliders", id, type, 1.0, colliderColor(c));
    if (c.shape == ColliderPose::Shape::Mesh)
    {
      solid.mesh_resource = c.mesh;
      solid.mesh_use_embedded_materials = false;  // its colour, as the other shapes
    }
    solid.pose = RosConverter::toPose(RigidPose{ c.position, c.orientation });
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
                                              visualization_msgs::Marker::SPHERE, c.size.x(), colliderColor(c));
      cap.pose = RosConverter::toPose(RigidPose{ c.position + axis, c.orientation });
      array.markers.push_back(cap);
    }
  }
}

/// A line from node a to node b if both ends are finite.
void addSegment(const NodeArray& x, int a, int b, visualization_msgs::Marker& lines)
{
  if (!x.col(a).allFinite() || !x.col(b).allFinite())
    return;
  lines.points.push_back(RosConverter::toPoint(x.col(a)));
  lines.points.push_back(RosConverter::toPoint(x.col(b)));
}

}  // namespace

namespace
{
/// Each rod as a LINE_STRIP of its diameter (id 2 in its body's namespace) and, in the namespace
/// "<body>/frames" (which rviz can hide on its own), each segment's material frame as three short lines
/// from its midpoint, red x along the rod, green y, blue z: a twist shows as the green and blue lines
/// turning about the rod.
void addRodMarkers(const Model& model, const State& state, const std::string& frame_id, const ros::Time& stamp,
                   visualization_msgs::MarkerArray& array)
{
  const NodeArray& x = state.position;
  std::vector<Eigen::Quaterniond> frames;
  for (std::size_t r = 0; r < model.rods.size(); ++r)
  {
    const Rod& rod = model.rods[r];
    const std::size_t b = model.bodyOf(rod.first);
    const std::string& name = model.bodies[b].name;
    visualization_msgs::Marker strip = marker(frame_id, stamp, name, 2, visualization_msgs::Marker::LINE_STRIP,
                                              2.0 * model.contact_radius[rod.first], rvizColor(model.bodies[b].look.color));
    visualization_msgs::Marker axes =
        marker(frame_id, stamp, name + "/frames", 0, visualization_msgs::Marker::LINE_LIST, 0.5 * kLineWidth, rvizColor(model.bodies[b].look.color));
    rodFrames(rod, x, state.twist, frames);
    const double length = 0.8 * rod.segment_length;
    for (int j = 0; j < rod.count; ++j)
    {
      const Vec3 p = x.col(rod.first + j);
      if (!p.allFinite())
        continue;
      strip.points.push_back(RosConverter::toPoint(p));
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
        axes.points.push_back(RosConverter::toPoint(middle));
        axes.points.push_back(RosConverter::toPoint(middle + length * axis.col(c)));
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
void addVolumeMarkers(const Model& model, const NodeArray& x, const std::string& frame_id, const ros::Time& stamp,
                      visualization_msgs::MarkerArray& array)
{
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    if (body.surface.empty())
      continue;
    visualization_msgs::Marker triangles =
        marker(frame_id, stamp, body.name, 2, visualization_msgs::Marker::TRIANGLE_LIST, 1.0, rvizColor(model.bodies[b].look.color));
    for (const std::array<int, 3>& t : body.surface)
      if (x.col(t[0]).allFinite() && x.col(t[1]).allFinite() && x.col(t[2]).allFinite())
        for (const int node : t)
          triangles.points.push_back(RosConverter::toPoint(x.col(node)));
    if (triangles.points.empty())
      triangles.action = visualization_msgs::Marker::DELETE;
    array.markers.push_back(triangles);
  }
}
}  // namespace

visualization_msgs::MarkerArray RosConverter::toMarkers(const World& world, const std::string& frame_id,
                                                        const ros::Time& stamp)
{
  return toMarkers(world.model(), world.state(), world.controllers(), world.colliderPoses(), frame_id, stamp);
}

visualization_msgs::MarkerArray RosConverter::toMarkers(const Model& model, const State& state,
                                                        const std::vector<BodyController>& controllers,
                                                        const std::vector<ColliderPose>& colliders,
                                                        const std::string& frame_id, const ros::Time& stamp)
{
  const NodeArray& x = state.position;
  visualization_msgs::MarkerArray array;
  std::vector<int> body_of_node(static_cast<std::size_t>(model.nodeCount()));
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    const std_msgs::ColorRGBA color = rvizColor(body.look.color);
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
        nodes.points.push_back(toPoint(x.col(i)));
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

  for (const BodyController& controlled : controllers)
  {
    const BodyRange& body = model.bodies[static_cast<std::size_t>(controlled.body)];
    int id = 2;
    for (const std::vector<Vec3>& curve : controlled.controller->curves(state))
    {
      visualization_msgs::Marker strip = marker(frame_id, stamp, body.name, id++, visualization_msgs::Marker::LINE_STRIP,
                                                2.0 * kLineWidth, rvizColor(body.look.color));
      for (const Vec3& p : curve)
        if (p.allFinite())
          strip.points.push_back(toPoint(p));
      array.markers.push_back(strip);
    }
  }
  addRodMarkers(model, state, frame_id, stamp, array);
  addVolumeMarkers(model, x, frame_id, stamp, array);
  addColliderMarkers(colliders, frame_id, stamp, array);
  return array;
}

visualization_msgs::MarkerArray RosConverter::toForceMarkers(const std::vector<Holder>& holders, double force_scale,
                                                             const std::string& frame_id, const ros::Time& stamp)
{
  visualization_msgs::MarkerArray array;
  // White: no default body hue (defaultBodyColor), and brighter than the colliders' default grey.
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
    arrow.points = { toPoint(holders[k].origin), toPoint(holders[k].origin + force_scale * holders[k].wrench.force) };
    array.markers.push_back(arrow);
  }
  return array;
}

}  // namespace soft_body_sim
