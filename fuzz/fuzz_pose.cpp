// libFuzzer harness for pose handling: any bytes are deserialized as a geometry_msgs/PoseStamped (as
// the node's subscriber does), checked by RosConverter::fromPose, applied to an anchor and stepped;
// the markers built from the result must hold no non-finite point (the node never publishes NaN).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <geometry_msgs/PoseStamped.h>
#include <ros/serialization.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/ros/ros_converter.h"

namespace
{
soft_body_sim::World makeRope()
{
  soft_body_sim::RopeDef rope;
  rope.nodes = 8;
  soft_body_sim::SceneDef scene;
  scene.bodies.push_back(soft_body_sim::buildRope("rope", rope));
  scene.bodies[0].anchors = { soft_body_sim::AnchorDef{ "end", 7 } };
  return soft_body_sim::buildWorld(scene);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  geometry_msgs::PoseStamped pose;
  try
  {
    ros::serialization::IStream stream(const_cast<std::uint8_t*>(data), static_cast<std::uint32_t>(size));
    ros::serialization::deserialize(stream, pose);
  }
  catch (const ros::serialization::StreamOverrunException&)
  {
    return 0;
  }
  soft_body_sim::World world = makeRope();
  soft_body_sim::Vec3 position;
  std::string why;
  if (!soft_body_sim::RosConverter::fromPose(pose.pose, position, why))
    return 0;
  world.moveAnchor(0, position);
  world.step();
  for (const visualization_msgs::Marker& marker : soft_body_sim::RosConverter::toMarkers(world, "world", ros::Time(1.0)).markers)
    for (const geometry_msgs::Point& p : marker.points)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        std::abort();
  return 0;
}
