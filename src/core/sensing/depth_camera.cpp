// DepthCamera: Embree 3 geometry for the scene's looks, colliders and planes, refitted per frame, and one
// ray per pixel (depth_camera.h).
#include "soft_body_sim/core/sensing/depth_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
namespace
{
/// How far planes reach from the point below the camera, in units of its max_range: far enough that a
/// floor fills the picture up to its horizon's last few pixels.
constexpr double kPlaneReach = 10.0;

/// The twelve triangles of a box's eight corners (corner k at the signs of bits 0, 1, 2 along x, y, z),
/// counter-clockwise seen from outside.
constexpr unsigned kBoxTriangles[12][3] = { { 0, 2, 3 }, { 0, 3, 1 }, { 4, 5, 7 }, { 4, 7, 6 }, { 0, 1, 5 }, { 0, 5, 4 },
                                            { 2, 6, 7 }, { 2, 7, 3 }, { 0, 4, 6 }, { 0, 6, 2 }, { 1, 3, 7 }, { 1, 7, 5 } };

/// Rays go out this many at a time along a row (Embree's packets: neighbouring pixels' rays meet the same
/// parts of the hierarchy, which it then walks once for all of them; 16 fill an AVX-512 register).
constexpr int kLanes = 16;

/// Who a geometry belongs to: its mask value and its colour.
struct Owner
{
  std::uint16_t mask = 0;
  Eigen::Vector3f color = Eigen::Vector3f::Zero();
};

/// A geometry attached to one of the camera's two Embree scenes (ids unique across both).
struct Geometry
{
  RTCGeometry handle = nullptr;
  Owner owner;
  bool round = false;       ///< curves or points (in `rounds`), else triangles (in `surfaces`)
  std::size_t vertices = 0;
  bool enabled = true;      ///< a collider not yet placed is disabled
};

Eigen::Vector3f relative(const Vec3& point, const Vec3& eye) { return (point - eye).cast<float>(); }

/// Writes a point into a vertex buffer's three floats at `at`.
void put(float* at, const Eigen::Vector3f& point)
{
  at[0] = point.x();
  at[1] = point.y();
  at[2] = point.z();
}

}  // namespace

struct DepthCamera::Scene
{
  /// A body's geometries (Look): its faces, tubes and balls, each absent (RTC_INVALID_GEOMETRY_ID) if empty.
  struct Body
  {
    Look look;  ///< a copy: the camera outlives a reset's new model
    int first = 0, count = 0;
    unsigned faces = RTC_INVALID_GEOMETRY_ID, tubes = RTC_INVALID_GEOMETRY_ID, balls = RTC_INVALID_GEOMETRY_ID;
  };
  /// A shape collider's geometry: its shape, size and name as ColliderPose::of gives them (the pose is the
  /// frame's), a mesh's triangles.
  struct Collider
  {
    ColliderPose shape;
    std::shared_ptr<const TriangleMesh> mesh;
    unsigned geometry = RTC_INVALID_GEOMETRY_ID;
  };
  struct PlaneGeometry
  {
    Plane plane;
    unsigned geometry = RTC_INVALID_GEOMETRY_ID;
  };

  CameraDef def;
  CameraIntrinsics intrinsics;
  RTCDevice device = nullptr;
  // Triangles and round geometry (curves, points) in scenes of their own: Embree walks round geometry's
  // hierarchy one ray at a time even in a packet, at 20 ns a ray (measured), so only the packets whose
  // pixels can see some of it (roundPackets) look into `rounds`, after `surfaces`.
  RTCScene surfaces = nullptr;
  RTCScene rounds = nullptr;
  std::vector<Geometry> geometries;  ///< by id
  /// Per packet of kLanes pixels of a row (row-major): whether any round geometry's box projects onto it.
  std::vector<std::uint8_t> round_packets;
  std::vector<Body> bodies;
  std::vector<Collider> colliders;
  std::vector<PlaneGeometry> planes;

  Scene(const CameraDef& camera, const Model& model);
  ~Scene()
  {
    for (const RTCScene scene : { surfaces, rounds })
      if (scene)
        rtcReleaseScene(scene);
    if (device)
      rtcReleaseDevice(device);
  }

  /// A new geometry of `type` attached for `owner` (triangles to `surfaces`, the rest to `rounds`),
  /// refitted rather than rebuilt; its id.
  unsigned add(RTCGeometryType type, const Owner& owner, std::size_t vertices, RTCFormat vertex_format,
               std::size_t vertex_size, std::size_t primitives, RTCFormat index_format, std::size_t index_size)
  {
    RTCGeometry geometry = rtcNewGeometry(device, type);
    rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, vertex_format, vertex_size, vertices);
    if (primitives > 0)
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, index_format, index_size, primitives);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
    const bool round = type != RTC_GEOMETRY_TYPE_TRIANGLE;
    const auto id = static_cast<unsigned>(geometries.size());
    rtcAttachGeometryByID(round ? rounds : surfaces, geometry, id);
    rtcReleaseGeometry(geometry);  // its scene holds it
    geometries.push_back(Geometry{ geometry, owner, round, vertices });
    return id;
  }
  unsigned addTriangles(const Owner& owner, std::size_t vertices, const std::vector<std::array<unsigned, 3>>& triangles)
  {
    const unsigned id = add(RTC_GEOMETRY_TYPE_TRIANGLE, owner, vertices, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                            triangles.size(), RTC_FORMAT_UINT3, 3 * sizeof(unsigned));
    auto* index = static_cast<unsigned*>(rtcGetGeometryBufferData(geometries[id].handle, RTC_BUFFER_TYPE_INDEX, 0));
    for (const std::array<unsigned, 3>& t : triangles)
      for (const unsigned corner : t)
        *index++ = corner;
    return id;
  }
  /// Linear curves (round: tubes with round ends; cone: capped cylinders) of one segment per pair of vertices.
  unsigned addSegments(RTCGeometryType type, const Owner& owner, std::size_t segments)
  {
    const unsigned id = add(type, owner, 2 * segments, RTC_FORMAT_FLOAT4, 4 * sizeof(float), segments,
                            RTC_FORMAT_UINT, sizeof(unsigned));
    auto* index = static_cast<unsigned*>(rtcGetGeometryBufferData(geometries[id].handle, RTC_BUFFER_TYPE_INDEX, 0));
    for (std::size_t k = 0; k < segments; ++k)
      index[k] = static_cast<unsigned>(2 * k);
    return id;
  }
  unsigned addPoints(const Owner& owner, std::size_t points)
  {
    return add(RTC_GEOMETRY_TYPE_SPHERE_POINT, owner, points, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 0,
               RTC_FORMAT_UNDEFINED, 0);
  }

  float* vertices(unsigned id) const
  {
    return static_cast<float*>(rtcGetGeometryBufferData(geometries[id].handle, RTC_BUFFER_TYPE_VERTEX, 0));
  }
  void commit(unsigned id) const
  {
    RTCGeometry geometry = geometries[id].handle;
    rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geometry);
  }

  void placeBodies(const State& state, const Vec3& eye) const;
  void placeColliders(const std::vector<ColliderPose>& poses, const Vec3& eye);
  void placePlanes(const Vec3& eye) const;
  void markRoundPackets(const Eigen::Matrix3f& optical);
};

DepthCamera::Scene::Scene(const CameraDef& camera, const Model& model)
  : def(camera), intrinsics(CameraIntrinsics::of(camera))
{
  // One thread: the refit costs 0.1 ms a frame, and Embree's default thread pool (TBB) would keep workers
  // spinning beside the physics step after every frame's commit.
  device = rtcNewDevice("threads=1");
  if (!device)
    throw std::runtime_error("camera '" + camera.name + "': Embree could not start (rtcNewDevice failed)");
  for (RTCScene* scene : { &surfaces, &rounds })
  {
    *scene = rtcNewScene(device);
    rtcSetSceneFlags(*scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(*scene, RTC_BUILD_QUALITY_LOW);
  }

  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& range = model.bodies[b];
    const Look& look = range.look;
    const Owner owner{ static_cast<std::uint16_t>(1 + b), look.color.cast<float>() };
    Body body;
    body.look = look;
    body.first = range.first;
    body.count = range.count;
    if (!look.faces.empty())
    {
      std::vector<std::array<unsigned, 3>> faces;
      for (const std::array<int, 3>& face : look.faces)
        faces.push_back({ static_cast<unsigned>(face[0] - range.first), static_cast<unsigned>(face[1] - range.first),
                          static_cast<unsigned>(face[2] - range.first) });
      body.faces = addTriangles(owner, static_cast<std::size_t>(range.count), faces);
    }
    if (!look.tubes.empty())
      body.tubes = addSegments(RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE, owner, look.tubes.size());
    if (!look.balls.empty())
      body.balls = addPoints(owner, look.balls.size());
    bodies.push_back(body);
  }

  // Mask values follow ~state's colliders: the named planes, then every shape in placements() order.
  std::uint16_t index = kColliderMask;
  for (const Plane& plane : model.colliders.planes)
  {
    if (!plane.name.empty())
      ++index;
    std::vector<std::array<unsigned, 3>> square = { { 0, 1, 2 }, { 0, 2, 3 } };
    planes.push_back({ plane, addTriangles(Owner{ 0, plane.color.cast<float>() }, 4, square) });
  }
  const auto addShape = [&](const ColliderPose& shape, const std::shared_ptr<const TriangleMesh>& mesh) {
    Collider collider{ shape, mesh };
    const Owner owner{ index++, shape.color.cast<float>() };
    std::vector<std::array<unsigned, 3>> triangles;
    switch (shape.shape)
    {
      case ColliderPose::Shape::Sphere:
        collider.geometry = addPoints(owner, 1);
        break;
      case ColliderPose::Shape::Capsule:
        collider.geometry = addSegments(RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE, owner, 1);
        break;
      case ColliderPose::Shape::Cylinder:
        collider.geometry = addSegments(RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE, owner, 1);
        break;
      case ColliderPose::Shape::Box:
        for (const auto& t : kBoxTriangles)
          triangles.push_back({ t[0], t[1], t[2] });
        collider.geometry = addTriangles(owner, 8, triangles);
        break;
      case ColliderPose::Shape::Mesh:
        if (!mesh || mesh->triangles.empty())
          break;
        for (const Eigen::Vector3i& t : mesh->triangles)
          triangles.push_back({ static_cast<unsigned>(t[0]), static_cast<unsigned>(t[1]), static_cast<unsigned>(t[2]) });
        collider.geometry = addTriangles(owner, mesh->vertices.size(), triangles);
        break;
    }
    colliders.push_back(collider);
  };
  for (const Sphere& sphere : model.colliders.spheres)
    addShape(ColliderPose::of(sphere), nullptr);
  for (const Capsule& capsule : model.colliders.capsules)
    addShape(ColliderPose::of(capsule), nullptr);
  for (const Box& box : model.colliders.boxes)
    addShape(ColliderPose::of(box), nullptr);
  for (const Cylinder& cylinder : model.colliders.cylinders)
    addShape(ColliderPose::of(cylinder), nullptr);
  for (const Mesh& mesh : model.colliders.meshes)
    addShape(ColliderPose::of(mesh), mesh.triangles);
}

void DepthCamera::Scene::placeBodies(const State& state, const Vec3& eye) const
{
  for (const Body& body : bodies)
  {
    const Look& look = body.look;
    const auto node = [&](int i) { return relative(state.position.col(i), eye); };
    if (body.faces != RTC_INVALID_GEOMETRY_ID)
    {
      float* v = vertices(body.faces);
      for (int i = 0; i < body.count; ++i)
        put(v + 3 * i, node(body.first + i));
      commit(body.faces);
    }
    const auto ball = [&](float* at, int i) {
      put(at, node(i));
      at[3] = static_cast<float>(look.radius);
    };
    if (body.tubes != RTC_INVALID_GEOMETRY_ID)
    {
      float* v = vertices(body.tubes);
      for (std::size_t k = 0; k < look.tubes.size(); ++k)
      {
        ball(v + 8 * k, look.tubes[k].first);
        ball(v + 8 * k + 4, look.tubes[k].second);
      }
      commit(body.tubes);
    }
    if (body.balls != RTC_INVALID_GEOMETRY_ID)
    {
      float* v = vertices(body.balls);
      for (std::size_t k = 0; k < look.balls.size(); ++k)
        ball(v + 4 * k, look.balls[k]);
      commit(body.balls);
    }
  }
}

void DepthCamera::Scene::placeColliders(const std::vector<ColliderPose>& poses, const Vec3& eye)
{
  for (Collider& collider : colliders)
  {
    if (collider.geometry == RTC_INVALID_GEOMETRY_ID)
      continue;
    const ColliderPose* pose = nullptr;
    for (const ColliderPose& p : poses)
      if (p.name == collider.shape.name)
        pose = &p;
    Geometry& geometry = geometries[collider.geometry];
    if (!pose)
    {
      if (geometry.enabled)
        rtcDisableGeometry(geometry.handle);
      geometry.enabled = false;
      continue;
    }
    if (!geometry.enabled)
      rtcEnableGeometry(geometry.handle);
    geometry.enabled = true;
    const Eigen::Quaterniond turn = pose->orientation.normalized();
    const auto local = [&](const Vec3& p) { return relative(pose->position + turn * p, eye); };
    float* v = vertices(collider.geometry);
    // ColliderPose's size: a sphere's diameter thrice, a capsule's or cylinder's (diameter, diameter,
    // length), a box's edges.
    const Vec3& size = collider.shape.size;
    const float radius = static_cast<float>(0.5 * size.x());
    switch (collider.shape.shape)
    {
      case ColliderPose::Shape::Sphere:
        put(v, local(Vec3::Zero()));
        v[3] = radius;
        break;
      case ColliderPose::Shape::Capsule:
      case ColliderPose::Shape::Cylinder:
        for (const int end : { 0, 1 })
        {
          put(v + 4 * end, local(Vec3(0.0, 0.0, (end == 0 ? -0.5 : 0.5) * size.z())));
          v[4 * end + 3] = radius;
        }
        break;
      case ColliderPose::Shape::Box:
        for (int k = 0; k < 8; ++k)
        {
          const Vec3 corner(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
          put(v + 3 * k, local(corner.cwiseProduct(size)));
        }
        break;
      case ColliderPose::Shape::Mesh:
        for (std::size_t k = 0; k < collider.mesh->vertices.size(); ++k)
          put(v + 3 * k, local(collider.mesh->vertices[k]));
        break;
    }
    commit(collider.geometry);
  }
}

void DepthCamera::Scene::placePlanes(const Vec3& eye) const
{
  const double reach = kPlaneReach * def.max_range;
  for (const PlaneGeometry& at : planes)
  {
    const Vec3 n = at.plane.normal.normalized();
    const Vec3 foot = eye - n * n.dot(eye - at.plane.point);
    const Vec3 t1 = n.unitOrthogonal() * reach;
    const Vec3 t2 = n.cross(t1);
    float* v = vertices(at.geometry);
    const Vec3 corners[4] = { foot - t1 - t2, foot + t1 - t2, foot + t1 + t2, foot - t1 + t2 };
    for (int k = 0; k < 4; ++k)
      put(v + 3 * k, relative(corners[k], eye));
    commit(at.geometry);
  }
}

void DepthCamera::Scene::markRoundPackets(const Eigen::Matrix3f& optical)
{
  const int columns = (intrinsics.width + kLanes - 1) / kLanes;
  round_packets.assign(static_cast<std::size_t>(columns) * static_cast<std::size_t>(intrinsics.height), 0);
  const auto mark = [&](int u0, int u1, int v0, int v1) {
    for (int v = std::max(v0, 0); v <= std::min(v1, intrinsics.height - 1); ++v)
      for (int c = std::max(u0, 0) / kLanes; c <= std::min(u1, intrinsics.width - 1) / kLanes; ++c)
        round_packets[static_cast<std::size_t>(v) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(c)] = 1;
  };
  for (const Geometry& geometry : geometries)
  {
    if (!geometry.round || !geometry.enabled)
      continue;
    // Its box (every vertex's ball: x y z radius, relative to the camera), its eight corners in the
    // optical frame and their pixels: the box's picture lies within theirs when all are in front.
    const float* v = static_cast<const float*>(rtcGetGeometryBufferData(geometry.handle, RTC_BUFFER_TYPE_VERTEX, 0));
    Eigen::AlignedBox3f box;
    for (std::size_t k = 0; k < geometry.vertices; ++k)
    {
      const Eigen::Vector3f centre(v[4 * k], v[4 * k + 1], v[4 * k + 2]);
      box.extend(centre - Eigen::Vector3f::Constant(v[4 * k + 3])).extend(centre + Eigen::Vector3f::Constant(v[4 * k + 3]));
    }
    int behind = 0;
    Eigen::Vector2f low = Eigen::Vector2f::Constant(std::numeric_limits<float>::infinity()), high = -low;
    for (int c = 0; c < 8; ++c)
    {
      const Eigen::Vector3f p = optical.transpose() * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
      if (p.z() <= 0.0f)
      {
        ++behind;
        continue;
      }
      const Eigen::Vector2f pixel(static_cast<float>(intrinsics.fx) * p.x() / p.z() + static_cast<float>(intrinsics.cx),
                                  static_cast<float>(intrinsics.fy) * p.y() / p.z() + static_cast<float>(intrinsics.cy));
      low = low.cwiseMin(pixel);
      high = high.cwiseMax(pixel);
    }
    if (behind == 8)
      continue;
    if (behind > 0)  // it reaches behind the camera: it may be anywhere in the picture
      mark(0, intrinsics.width - 1, 0, intrinsics.height - 1);
    else if (high.x() >= -1.0f && high.y() >= -1.0f && low.x() <= intrinsics.width && low.y() <= intrinsics.height)
      mark(static_cast<int>(std::floor(low.x())) - 1, static_cast<int>(std::ceil(high.x())) + 1,
           static_cast<int>(std::floor(low.y())) - 1, static_cast<int>(std::ceil(high.y())) + 1);
  }
}

std::vector<std::uint16_t> depthMillimetres(const CameraImage& image)
{
  std::vector<std::uint16_t> millimetres(image.depth.size(), 0);
  for (std::size_t k = 0; k < image.depth.size(); ++k)
  {
    const double mm = std::round(1000.0 * static_cast<double>(image.depth[k]));
    if (mm >= 1.0 && mm <= 65535.0)  // NaN fails both
      millimetres[k] = static_cast<std::uint16_t>(mm);
  }
  return millimetres;
}

DepthCamera::DepthCamera(const CameraDef& camera, const Model& model)
{
  checkCamera(camera);
  scene_ = std::make_unique<Scene>(camera, model);
}

DepthCamera::~DepthCamera() = default;

const CameraIntrinsics& DepthCamera::intrinsics() const { return scene_->intrinsics; }

CameraImage DepthCamera::render(const State& state, const std::vector<ColliderPose>& colliders, const RigidPose& link,
                                std::uint64_t frame_number)
{
  CameraImage image;
  render(state, colliders, link, frame_number, image);
  return image;
}

void DepthCamera::render(const State& state, const std::vector<ColliderPose>& colliders, const RigidPose& link,
                         std::uint64_t frame_number, CameraImage& image)
{
  Scene& s = *scene_;
  const Vec3 eye = link.position;
  s.placeBodies(state, eye);
  s.placeColliders(colliders, eye);
  s.placePlanes(eye);
  rtcCommitScene(s.surfaces);
  rtcCommitScene(s.rounds);

  const CameraIntrinsics& k = s.intrinsics;
  const CameraDef& def = s.def;
  image.width = k.width;
  image.height = k.height;
  const std::size_t pixels = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
  image.depth.resize(pixels);  // every pixel is written below
  image.color.resize(3 * pixels);
  image.mask.resize(pixels);
  // The optical frame's axes in the scene frame: a pixel's ray (x, y, 1) in it has t = z along it.
  const Eigen::Matrix3f optical = (link.orientation.normalized() * linkToOptical()).toRotationMatrix().cast<float>();
  s.markRoundPackets(optical);
  const int columns = (k.width + kLanes - 1) / kLanes;
  std::mt19937_64 random(def.noise ? def.noise->seed ^ (0x9E3779B97F4A7C15ull * (frame_number + 1)) : 0);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  // Rounded to the nearest of 0..255 (std::lround's call cost a fifth of the frame).
  const auto channel = [](float value) { return static_cast<std::uint8_t>(255.0f * std::clamp(value, 0.0f, 1.0f) + 0.5f); };
  const Eigen::Vector3f background = def.background.cast<float>();
  // A pixel's ray is linear in its column: the row's first ray plus u times the step between columns.
  const Eigen::Vector3f column_step = optical * Eigen::Vector3f(static_cast<float>(1.0 / k.fx), 0.0f, 0.0f);
  for (int v = 0; v < k.height; ++v)
  {
    const Eigen::Vector3f row_start =
        optical * Eigen::Vector3f(static_cast<float>(-k.cx / k.fx), static_cast<float>((v - k.cy) / k.fy), 1.0f);
    for (int u0 = 0; u0 < k.width; u0 += kLanes)
    {
      alignas(64) int valid[kLanes];
      alignas(64) RTCRayHit16 rays;
      Eigen::Vector3f directions[kLanes];
      for (int i = 0; i < kLanes; ++i)
      {
        const int u = std::min(u0 + i, k.width - 1);
        valid[i] = u0 + i < k.width ? -1 : 0;
        directions[i] = row_start + static_cast<float>(u) * column_step;
        rays.ray.org_x[i] = rays.ray.org_y[i] = rays.ray.org_z[i] = 0.0f;
        rays.ray.dir_x[i] = directions[i].x();
        rays.ray.dir_y[i] = directions[i].y();
        rays.ray.dir_z[i] = directions[i].z();
        rays.ray.tnear[i] = 0.0f;
        rays.ray.tfar[i] = std::numeric_limits<float>::infinity();
        rays.ray.time[i] = 0.0f;
        rays.ray.mask[i] = ~0u;
        rays.ray.id[i] = 0;
        rays.ray.flags[i] = 0;
        rays.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rays.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, s.surfaces, &context, &rays);
      // Round geometry nearer than the surface hit (tfar is now its distance) replaces it.
      if (s.round_packets[static_cast<std::size_t>(v) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(u0 / kLanes)])
        rtcIntersect16(valid, s.rounds, &context, &rays);
      for (int i = 0; i < kLanes && u0 + i < k.width; ++i)
      {
        const std::size_t pixel =
            static_cast<std::size_t>(v) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(u0 + i);
        Eigen::Vector3f color = background;
        image.mask[pixel] = 0;
        image.depth[pixel] = std::numeric_limits<float>::quiet_NaN();
        if (rays.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID)
        {
          const Owner& owner = s.geometries[rays.hit.geomID[i]].owner;
          image.mask[pixel] = owner.mask;
          const Eigen::Vector3f normal(rays.hit.Ng_x[i], rays.hit.Ng_y[i], rays.hit.Ng_z[i]);
          const float norms = normal.norm() * directions[i].norm();
          const float lambert = norms > 0.0f ? std::abs(normal.dot(directions[i])) / norms : 0.0f;
          color = owner.color * lambert;
          const double z = rays.ray.tfar[i];
          if (z >= def.min_range && z <= def.max_range)
          {
            const double noise = def.noise ? def.noise->depth_stddev * z * z * unit_normal(random) : 0.0;
            image.depth[pixel] = static_cast<float>(z + noise);
          }
        }
        for (int c = 0; c < 3; ++c)
          image.color[3 * pixel + static_cast<std::size_t>(c)] = channel(color[c]);
      }
    }
  }
}

}  // namespace soft_body_sim
