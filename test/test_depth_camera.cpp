// The simulated RGB-D camera (sensing/depth_camera.h) against closed forms: a tilted box face's depth is
// the ray-plane distance at every pixel, a sphere's and a cylinder's silhouettes have their analytic radii,
// the nearest surface owns each pixel (a rope before a box, a sphere before a cloth), the noise has its
// configured spread, and nothing outside [min_range, max_range] returns a depth.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <numeric>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/core/sensing/depth_camera.h"

namespace soft_body_sim
{
namespace
{
/// A camera of 161 x 121 px (its centre a pixel: cx = 80, cy = 60) with a 60 degree field of view.
CameraDef smallCamera()
{
  CameraDef camera;
  camera.name = "camera";
  camera.width = 161;
  camera.height = 121;
  camera.horizontal_fov = 60.0;
  return camera;
}

/// A scene with one unseen ball far behind every camera here, and the given colliders.
SceneDef sceneWith(const Colliders& colliders)
{
  SceneDef scene;
  scene.colliders = colliders;
  BodyDef speck;
  speck.name = "speck";
  speck.nodes.push_back(NodeDef{ Vec3(-100.0, 0.0, 0.0), 1.0, Vec3::Zero(), true });
  scene.bodies.push_back(speck);
  return scene;
}

/// The scene frame's direction of pixel (u, v)'s ray from a link at `link`, with optical z = 1.
Vec3 ray(const CameraIntrinsics& k, const Eigen::Quaterniond& link, int u, int v)
{
  return link * linkToOptical() * Vec3((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
}

std::size_t at(const CameraImage& image, int u, int v) { return static_cast<std::size_t>(v * image.width + u); }

TEST(DepthCamera, EveryPixelOfATiltedBoxFaceHasTheRayPlaneDistanceAndBackProjectsOntoTheFace)
{
  Box box;
  box.at.name = "box";
  box.size = Vec3(0.2, 0.8, 0.6);
  box.at.position = Vec3(1.8, -0.1, 1.1);
  box.at.orientation = Eigen::AngleAxisd(0.35, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitY());
  Colliders colliders;
  colliders.boxes.push_back(box);
  World world = buildWorld(sceneWith(colliders));
  DepthCamera camera(smallCamera(), world.model());
  const RigidPose link{ Vec3(0.3, -0.2, 1.0), Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Vec3::UnitZ())) };
  const CameraImage image = camera.render(world.state(), world.colliderPoses(), link, 0);
  const CameraIntrinsics& k = camera.intrinsics();
  // The face toward the camera: local -x.
  const Vec3 normal = box.at.orientation * -Vec3::UnitX();
  const Vec3 point = box.at.position + box.at.orientation * Vec3(-0.1, 0.0, 0.0);
  int checked = 0;
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u)
    {
      const Vec3 d = ray(k, link.orientation, u, v);
      const double t = normal.dot(point - link.position) / normal.dot(d);
      const Vec3 local = box.at.orientation.conjugate() * (link.position + t * d - box.at.position);
      if (!(std::abs(local.y()) < 0.4 - 0.005 && std::abs(local.z()) < 0.3 - 0.005))
        continue;  // not on the face, or within 5 mm of its edges
      ++checked;
      const std::size_t pixel = at(image, u, v);
      ASSERT_EQ(image.mask[pixel], kColliderMask) << u << ", " << v;
      ASSERT_NEAR(image.depth[pixel], t, 1e-4) << u << ", " << v;
      const Vec3 back = link.position + static_cast<double>(image.depth[pixel]) * d;
      ASSERT_NEAR(normal.dot(back - point), 0.0, 1e-4);
      // 16UC1 (millimetres, rounded) is within 1 mm of it.
      ASSERT_NEAR(std::round(1000.0 * image.depth[pixel]) / 1000.0, t, 1e-3);
    }
  EXPECT_GT(checked, 2000);
}

TEST(DepthCamera, ASpheresAndACylindersSilhouettesHaveTheirAnalyticRadii)
{
  // On the optical axis at distance D, a sphere of radius r subtends asin(r / D): a circle of fx tan(asin(r / D))
  // pixels. A cylinder seen end-on is its cap, a disc of radius r at D - length / 2: fx r / (D - length / 2).
  Sphere sphere;
  sphere.at.name = "ball";
  sphere.radius = 0.1;
  sphere.at.position = Vec3(1.0, 0.0, 0.0);
  Cylinder cylinder;
  cylinder.at.name = "can";
  cylinder.radius = 0.15;
  cylinder.length = 0.4;
  cylinder.at.position = Vec3(0.0, 2.0, 0.0);
  cylinder.at.orientation = Eigen::AngleAxisd(-0.5 * M_PI, Vec3::UnitX());  // its axis along y
  Colliders colliders;
  colliders.spheres.push_back(sphere);
  colliders.cylinders.push_back(cylinder);
  World world = buildWorld(sceneWith(colliders));
  DepthCamera camera(smallCamera(), world.model());
  const CameraIntrinsics& k = camera.intrinsics();
  const auto across = [&](const CameraImage& image, std::uint16_t mask) {
    int row = 0, column = 0;
    for (int u = 0; u < k.width; ++u)
      row += image.mask[at(image, u, 60)] == mask;
    for (int v = 0; v < k.height; ++v)
      column += image.mask[at(image, 80, v)] == mask;
    return std::pair<int, int>(row, column);
  };
  const CameraImage ball = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 0);
  const double ball_radius = k.fx * std::tan(std::asin(0.1 / 1.0));
  EXPECT_NEAR(across(ball, kColliderMask).first, 2.0 * ball_radius, 2.0);
  EXPECT_NEAR(across(ball, kColliderMask).second, 2.0 * ball_radius, 2.0);
  EXPECT_NEAR(ball.depth[at(ball, 80, 60)], 0.9, 1e-4);
  // Looking along +y (the link turned a quarter about z) at the cylinder's cap.
  const RigidPose turned{ Vec3::Zero(), Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitZ())) };
  const CameraImage can = camera.render(world.state(), world.colliderPoses(), turned, 0);
  const double can_radius = k.fx * 0.15 / 1.8;
  EXPECT_NEAR(across(can, kColliderMask + 1).first, 2.0 * can_radius, 2.0);
  EXPECT_NEAR(across(can, kColliderMask + 1).second, 2.0 * can_radius, 2.0);
  for (const auto& [u, v] : { std::pair<int, int>(80, 60), { 70, 55 }, { 88, 64 } })
    EXPECT_NEAR(can.depth[at(can, u, v)], 1.8, 1e-4) << u << ", " << v;  // the flat cap
}

TEST(DepthCamera, ARopeBeforeABoxOwnsItsPixelsWithItsOwnDepth)
{
  // A rope of radius 2 cm along y at x = 1 m in the camera's horizontal plane, a box's face at x = 1.9 m
  // behind it: along the centre row the rope's front, 0.98 m; above and below it the box.
  Box box;
  box.at.name = "wall";
  box.size = Vec3(0.2, 4.0, 4.0);
  box.at.position = Vec3(2.0, 0.0, 0.0);
  Colliders colliders;
  colliders.boxes.push_back(box);
  SceneDef scene = sceneWith(colliders);
  BodyDef rope;
  rope.name = "rope";
  rope.contact_radius = 0.02;
  for (int i = 0; i <= 10; ++i)
    rope.nodes.push_back(NodeDef{ Vec3(1.0, -0.25 + 0.05 * i, 0.0), 0.01, Vec3::Zero(), true });
  for (int i = 0; i < 10; ++i)
    rope.springs.push_back(SpringDef{ i, i + 1, 100.0, 0.0, std::nullopt });
  scene.bodies.push_back(rope);
  World world = buildWorld(scene);
  DepthCamera camera(smallCamera(), world.model());
  const CameraImage image = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 0);
  const CameraIntrinsics& k = camera.intrinsics();
  const int half_span = static_cast<int>(k.fx * 0.25 / 0.98) - 2;  // the rope's ends, and its round caps
  for (int u = 80 - half_span; u <= 80 + half_span; ++u)
  {
    EXPECT_EQ(image.mask[at(image, u, 60)], 2) << u;  // 1 + the rope's index
    EXPECT_NEAR(image.depth[at(image, u, 60)], 0.98, 1e-4) << u;
  }
  const int clear = static_cast<int>(std::ceil(k.fy * 0.02 / 0.98)) + 2;  // rows beyond the rope's radius
  for (const int v : { 60 - clear, 60 + clear, 10, 110 })
  {
    EXPECT_EQ(image.mask[at(image, 80, v)], kColliderMask) << v;
    EXPECT_NEAR(image.depth[at(image, 80, v)], 1.9, 1e-4) << v;
  }
  // The rope moved 0.5 m away: the next frame refits its tubes there.
  const int first = world.model().bodies[1].first;
  for (int i = 0; i <= 10; ++i)
    world.setNode(first + i, Vec3(1.5, -0.25 + 0.05 * i, 0.0), Vec3::Zero());
  const CameraImage moved = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 1);
  EXPECT_EQ(moved.mask[at(moved, 80, 60)], 2);
  EXPECT_NEAR(moved.depth[at(moved, 80, 60)], 1.48, 1e-4);
}

/// A straight rope of radius `radius` from `from` to `to` (11 nodes, held), as a body of the scene.
BodyDef straightRope(const std::string& name, const Vec3& from, const Vec3& to, double radius)
{
  BodyDef rope;
  rope.name = name;
  rope.contact_radius = radius;
  for (int i = 0; i <= 10; ++i)
    rope.nodes.push_back(NodeDef{ from + (to - from) * (i / 10.0), 0.01, Vec3::Zero(), true });
  for (int i = 0; i < 10; ++i)
    rope.springs.push_back(SpringDef{ i, i + 1, 100.0, 0.0, std::nullopt });
  return rope;
}

/// The distance between the ray from the origin along `direction` (t >= 0) and the segment [a, b]: a
/// brute-force minimum over both parameters, on fine grids refined around the best.
double rayToSegment(const Vec3& direction, const Vec3& a, const Vec3& b)
{
  const Vec3 d = direction.normalized();
  double best = std::numeric_limits<double>::infinity();
  double s_best = 0.5;
  for (double width = 0.5; width > 1e-7; width *= 0.05)
  {
    const double centre = s_best;
    for (int k = -100; k <= 100; ++k)
    {
      const double s = std::clamp(centre + width * k / 100.0, 0.0, 1.0);
      const Vec3 p = a + s * (b - a);
      const double t = std::max(0.0, p.dot(d));
      const double distance = (p - t * d).norm();
      if (distance < best)
      {
        best = distance;
        s_best = s;
      }
    }
  }
  return best;
}

TEST(DepthCamera, RopesReachingBehindTheCameraOrPastThePicturesEdgeAreSeenWhereverTheyAre)
{
  // Round geometry (ropes, capsules, spheres) is looked for only in the pixels its box projects onto: a
  // rope from 1 m behind the camera to 3 m ahead of it (its box straddles the camera's plane) and, alone
  // in another scene, one running out of the picture sideways must still own exactly the pixels whose
  // rays pass within its radius, as a brute-force distance from each pixel's ray to the rope says (away
  // from the silhouette's edge: within 20 % of the radius).
  const double radius = 0.02;
  const Vec3 ends[2][2] = { { Vec3(-1.0, 0.3, -0.1), Vec3(3.0, 0.3, -0.1) },
                            { Vec3(1.0, -2.0, 0.2), Vec3(1.0, 0.1, 0.2) } };
  for (int r = 0; r < 2; ++r)
  {
    SceneDef scene = sceneWith(Colliders{});
    scene.bodies.push_back(straightRope("rope", ends[r][0], ends[r][1], radius));
    World world = buildWorld(scene);
    DepthCamera camera(smallCamera(), world.model());
    const CameraImage image = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 0);
    const CameraIntrinsics& k = camera.intrinsics();
    int seen = 0;
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u)
      {
        const double distance = rayToSegment(ray(k, Eigen::Quaterniond::Identity(), u, v), ends[r][0], ends[r][1]);
        const std::uint16_t mask = image.mask[at(image, u, v)];
        if (distance < 0.8 * radius)
        {
          EXPECT_EQ(mask, 2) << r << ": " << u << " " << v;  // 1 + the rope's index
          seen += mask == 2;
        }
        else if (distance > 1.2 * radius)
        {
          EXPECT_EQ(mask, 0) << r << ": " << u << " " << v;
        }
      }
    EXPECT_GT(seen, 100) << r;  // in the picture, over many pixels
  }
}

TEST(DepthCamera, ASphereBeforeACanvasOfClothHidesItsPart)
{
  ClothDef cloth;
  cloth.nx = cloth.ny = 11;
  cloth.corners.top_left = Vec3(2.0, 0.5, 0.5);
  cloth.corners.top_right = Vec3(2.0, -0.5, 0.5);
  cloth.corners.bottom_left = Vec3(2.0, 0.5, -0.5);
  cloth.pinned = { 0 };
  Sphere sphere;
  sphere.at.name = "ball";
  sphere.radius = 0.1;
  sphere.at.position = Vec3(1.0, 0.0, 0.0);
  Colliders colliders;
  colliders.spheres.push_back(sphere);
  SceneDef scene = sceneWith(colliders);
  scene.bodies.push_back(buildCloth("cloth", cloth));
  World world = buildWorld(scene);
  DepthCamera camera(smallCamera(), world.model());
  const CameraImage image = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 0);
  EXPECT_EQ(image.mask[at(image, 80, 60)], kColliderMask);  // the sphere, before the cloth
  EXPECT_NEAR(image.depth[at(image, 80, 60)], 0.9, 1e-4);
  EXPECT_EQ(image.mask[at(image, 80, 40)], 2);  // the cloth above it (0.29 m up), at its depth
  EXPECT_NEAR(image.depth[at(image, 80, 40)], 2.0, 1e-4);
  EXPECT_EQ(image.mask[at(image, 2, 60)], 0);  // beside the cloth: nothing
  EXPECT_TRUE(std::isnan(image.depth[at(image, 2, 60)]));
}

/// A wall 2 cm thick and `extent` [m] wide and high, its face `distance` [m] along +x from the origin.
Colliders wallAhead(double distance, double extent)
{
  Box box;
  box.at.name = "wall";
  box.size = Vec3(0.02, extent, extent);
  box.at.position = Vec3(distance + 0.01, 0.0, 0.0);
  Colliders colliders;
  colliders.boxes.push_back(box);
  return colliders;
}

/// The standard deviation [m] of a flat face's depth at `distance` straight ahead, and the image.
std::pair<double, CameraImage> spread(double distance, std::uint64_t seed, std::uint64_t frame)
{
  World world = buildWorld(sceneWith(wallAhead(distance, 8.0)));
  CameraDef def = smallCamera();
  def.noise = DepthNoise{ 0.001, seed };
  DepthCamera camera(def, world.model());
  CameraImage image = camera.render(world.state(), world.colliderPoses(), RigidPose{}, frame);
  double sum = 0.0, squares = 0.0;
  for (const float z : image.depth)
  {
    sum += z - distance;
    squares += (z - distance) * (z - distance);
  }
  const double n = static_cast<double>(image.depth.size());
  return { std::sqrt(squares / n - (sum / n) * (sum / n)), image };
}

TEST(DepthCamera, DepthNoiseHasItsSpreadAtOneMetreFourTimesAtTwoAndRepeatsForTheSameSeedAndFrame)
{
  // 19,481 pixels: the sample's standard deviation is within 1.5 % of the true one (3 sigma).
  EXPECT_NEAR(spread(1.0, 1, 0).first, 0.001, 0.0001);
  EXPECT_NEAR(spread(2.0, 1, 0).first, 0.004, 0.0004);
  EXPECT_EQ(spread(1.0, 7, 3).second.depth, spread(1.0, 7, 3).second.depth);
  EXPECT_NE(spread(1.0, 7, 3).second.depth, spread(1.0, 7, 4).second.depth);
  EXPECT_NE(spread(1.0, 7, 3).second.depth, spread(1.0, 8, 3).second.depth);
}

TEST(DepthCamera, NothingNearerThanMinRangeOrFartherThanMaxRangeReturnsADepthThoughItIsSeen)
{
  for (const double distance : { 0.05, 15.0 })
  {
    World world = buildWorld(sceneWith(wallAhead(distance, 100.0)));
    DepthCamera camera(smallCamera(), world.model());  // 0.1 to 10 m
    const CameraImage image = camera.render(world.state(), world.colliderPoses(), RigidPose{}, 0);
    EXPECT_TRUE(std::isnan(image.depth[at(image, 80, 60)])) << distance;
    EXPECT_EQ(image.mask[at(image, 80, 60)], kColliderMask) << distance;
    EXPECT_GT(image.color[3 * at(image, 80, 60)], 100) << distance;  // lit, facing the camera: 0.6 grey
  }
}

TEST(DepthCamera, AFloorPlaneIsSeenToItsHorizonAndMaskedZero)
{
  SceneDef scene = sceneWith(Colliders{});
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.0 });
  World world = buildWorld(scene);
  DepthCamera camera(smallCamera(), world.model());
  // 1 m above the floor, looking 10 degrees down: the centre ray (the optical axis) meets it 1 / sin 10
  // = 5.76 m ahead; the top row looks 13 degrees up (half the vertical field of view is 23).
  const double down = 10.0 * M_PI / 180.0;
  const RigidPose link{ Vec3(0.0, 0.0, 1.0), Eigen::Quaterniond(Eigen::AngleAxisd(down, Vec3::UnitY())) };
  const CameraImage image = camera.render(world.state(), world.colliderPoses(), link, 0);
  EXPECT_EQ(image.mask[at(image, 80, 60)], 0);
  EXPECT_NEAR(image.depth[at(image, 80, 60)], 1.0 / std::sin(down), 1e-4);
  EXPECT_TRUE(std::isnan(image.depth[at(image, 80, 0)]));  // above the horizon: nothing
  EXPECT_EQ(image.color[3 * at(image, 80, 0)], 51);          // the background, 0.2 grey
}

TEST(DepthCamera, ABadDefinitionIsRefusedNamingItsKey)
{
  World world = buildWorld(sceneWith(Colliders{}));
  const auto refused = [&](const CameraDef& def, const std::string& key) {
    try
    {
      DepthCamera camera(def, world.model());
    }
    catch (const DefinitionError& e)
    {
      return std::find(e.keys().begin(), e.keys().end(), key) != e.keys().end();
    }
    return false;
  };
  CameraDef def = smallCamera();
  def.width = 0;
  EXPECT_TRUE(refused(def, "width"));
  def = smallCamera();
  def.horizontal_fov = 180.0;
  EXPECT_TRUE(refused(def, "horizontal_fov"));
  def = smallCamera();
  def.min_range = 2.0;
  def.max_range = 1.0;
  EXPECT_TRUE(refused(def, "max_range"));
}

}  // namespace
}  // namespace soft_body_sim
