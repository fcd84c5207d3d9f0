// A simulated RGB-D camera: the bodies, colliders and planes as a depth camera sees them, by ray casting
// through Embree 3 (Intel's ray-tracing kernels, Debian's libembree-dev), one ray per pixel.
//
// What it sees (Look, model.h): a rope's or rod's links as round tubes of its radius, a cloth's, jelly's or
// solid's faces as triangles, other nodes as balls; colliders as their shapes (sphere and capsule exactly,
// a cylinder as a capped cone of equal radii, a box and a mesh as their triangles); planes as squares
// reaching 10 times max_range from the point below the camera. The geometry's topology is built once; each
// frame moves its vertices and refits Embree's hierarchy rather than rebuilding it. Vertices are taken
// relative to the camera before Embree's single precision: a scene far from its origin (a UTM map frame)
// loses nothing. Rays go out 16 at a time along a row; round geometry (tubes, balls, spheres, capsules,
// cylinders), which Embree walks one ray at a time even in a packet, is in a scene of its own, looked into
// only by the packets its boxes project onto.
//
// Per pixel: the nearest surface along the pixel's ray, its colour shaded by Lambert's law under a light at
// the camera (rgb = colour |cos| of the angle between ray and surface, both sides lit), its body or
// collider in the mask, and its depth (the z of the hit in the optical frame) where min_range <= z <=
// max_range, else no return.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/sensing/camera_def.h"

namespace soft_body_sim
{
/// The mask value of collider k (its index in ~state's `colliders`: the named planes, then the shapes in
/// placements() order): kColliderMask + k.
constexpr std::uint16_t kColliderMask = 1000;

/// One frame of a camera, row by row from the top left pixel.
struct CameraImage
{
  int width = 0;
  int height = 0;
  std::vector<float> depth;          ///< [m] z of the hit in the optical frame; NaN: no return
  std::vector<std::uint8_t> color;   ///< rgb8, three per pixel
  /// 0: nothing or a plane; 1 + the body's index in the scene; kColliderMask + the collider's index among
  /// the scene's named planes and then its shapes (spheres, capsules, boxes, cylinders, meshes), as in
  /// ~state's `colliders`
  std::vector<std::uint16_t> mask;
};

/// The depth as whole millimetres, 0 = no return (sensor_msgs 16UC1, as the RealSense driver writes it;
/// beyond 65.535 m no return either).
std::vector<std::uint16_t> depthMillimetres(const CameraImage& image);

class DepthCamera
{
public:
  /// The camera `camera` (checked: checkCamera) on the scene `model` (its bodies' Look, its colliders;
  /// copied: a model rebuilt from the same scene, as by a reset, is seen as well).
  DepthCamera(const CameraDef& camera, const Model& model);
  ~DepthCamera();
  DepthCamera(const DepthCamera&) = delete;
  DepthCamera& operator=(const DepthCamera&) = delete;

  /// The frame seen from `link` (the pose of <name>_link in the scene frame) with the nodes at `state`'s
  /// positions and the placed colliders at `colliders` (World::colliderPoses; one not yet placed is not
  /// seen). `frame_number` draws the noise: the same number gives the same noise.
  /// Into `image`, whose buffers are reused (a camera's frames are all one size: no allocation after the
  /// first).
  void render(const State& state, const std::vector<ColliderPose>& colliders, const RigidPose& link,
              std::uint64_t frame_number, CameraImage& image);
  /// The same into a new image.
  CameraImage render(const State& state, const std::vector<ColliderPose>& colliders, const RigidPose& link,
                     std::uint64_t frame_number);

  const CameraIntrinsics& intrinsics() const;

private:
  struct Scene;
  std::unique_ptr<Scene> scene_;
};

}  // namespace soft_body_sim
