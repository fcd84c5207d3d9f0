// Snapshots of a world: in memory (a copy of the world) and as bytes (its values, state_archive.h).
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "soft_body_sim/core/world.h"

namespace soft_body_sim
{
namespace
{
/// The bytes' first eight, and the format's version: a new carried value or a change of one's meaning
/// makes a new version, which refuses the older bytes rather than misreading them.
constexpr char kMagic[8] = { 's', 'b', 's', 'n', 'a', 'p', '\r', '\n' };
constexpr std::uint32_t kFormatVersion = 6;
/// Reads as itself only on a machine of the writer's byte order.
constexpr std::uint32_t kByteOrder = 0x01020304;

/// FNV-1a, 64 bits: a fingerprint and a checksum against damage (not against a forger).
std::uint64_t hashOf(const char* data, std::size_t size)
{
  std::uint64_t hash = 14695981039346656037ull;
  for (std::size_t k = 0; k < size; ++k)
  {
    hash ^= static_cast<unsigned char>(data[k]);
    hash *= 1099511628211ull;
  }
  return hash;
}

/// What a scene is made of, to tell two apart: its bodies (name and node count) and its element counts.
std::string sceneSummary(const Model& model)
{
  std::string summary;
  for (const BodyRange& body : model.bodies)
    summary += (summary.empty() ? "" : ", ") + body.name + " (" + std::to_string(body.count) + " nodes)";
  return summary + "; " + std::to_string(model.springs.size()) + " springs, " +
         std::to_string(model.constraints.size()) + " constraints, " + std::to_string(model.rods.size()) +
         " rods, " + std::to_string(model.tetrahedra.size()) + " tetrahedra";
}

std::invalid_argument anotherScene(const std::string& theirs, const std::string& ours)
{
  return std::invalid_argument("World::restore: a snapshot of another scene (bodies " + theirs +
                               ") cannot be restored into this one (bodies " + ours + ")");
}

/// The header's values, in their order.
struct Header
{
  char magic[8];
  std::uint32_t byte_order = kByteOrder;
  std::uint32_t version = kFormatVersion;
  std::uint64_t fingerprint = 0;
  std::string summary;
  double time = 0.0;
  std::int64_t steps = 0;
  std::uint64_t checksum = 0;  ///< of all the bytes, these 8 (the header's last) taken as 0

  void carry(StateArchive& archive)
  {
    archive.bytes(magic, sizeof magic);
    archive(byte_order, version);
    if (archive.reading() && std::memcmp(magic, kMagic, sizeof magic) != 0)
      throw std::invalid_argument("snapshot bytes: these are not a soft_body_sim snapshot");
    if (archive.reading() && byte_order != kByteOrder)
      throw std::invalid_argument("snapshot bytes: written on a machine of another byte order");
    if (archive.reading() && version != kFormatVersion)
      throw std::invalid_argument("snapshot bytes: format version " + std::to_string(version) +
                                  ", this build reads version " + std::to_string(kFormatVersion));
    archive(fingerprint, summary, time, steps, checksum);
  }
};
}  // namespace

double WorldSnapshot::time() const { return world_ ? world_->time() : time_; }

std::int64_t WorldSnapshot::stepCount() const { return world_ ? world_->stepCount() : steps_; }

std::string WorldSnapshot::toBytes() const
{
  if (!world_)
    return *bytes_;
  World& world = *world_;
  std::string values;
  StateArchive writer(values);
  world.carry(writer);
  Header header;
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.fingerprint = world.fingerprint();
  header.summary = sceneSummary(world.model_);
  header.time = world.time();
  header.steps = world.stepCount();
  std::string bytes;
  StateArchive header_writer(bytes);
  header.carry(header_writer);
  bytes += values;
  const std::size_t at = bytes.size() - values.size() - sizeof header.checksum;
  header.checksum = hashOf(bytes.data(), bytes.size());
  std::memcpy(bytes.data() + at, &header.checksum, sizeof header.checksum);
  return bytes;
}

WorldSnapshot WorldSnapshot::fromBytes(std::string bytes)
{
  Header header;
  StateArchive reader(bytes.data(), bytes.size());
  header.carry(reader);
  WorldSnapshot snapshot;
  snapshot.body_ = bytes.size() - reader.left();
  const std::size_t at = snapshot.body_ - sizeof header.checksum;
  std::memset(bytes.data() + at, 0, sizeof header.checksum);
  const std::uint64_t checksum = hashOf(bytes.data(), bytes.size());
  std::memcpy(bytes.data() + at, &header.checksum, sizeof header.checksum);
  if (checksum != header.checksum)
    throw std::invalid_argument("snapshot bytes: damaged (their checksum does not match)");
  snapshot.fingerprint_ = header.fingerprint;
  snapshot.summary_ = std::move(header.summary);
  snapshot.time_ = header.time;
  snapshot.steps_ = header.steps;
  snapshot.bytes_ = std::make_shared<const std::string>(std::move(bytes));
  return snapshot;
}

std::uint64_t World::fingerprint() const
{
  // A world's own copy of what it was built with, so that nothing it changes as it runs counts.
  Model fixed;
  fixed.mass = model_.mass;
  fixed.contact_radius = model_.contact_radius;
  fixed.contact_segments = model_.contact_segments;
  fixed.contact_triangles = model_.contact_triangles;
  material_.builtElements(model_, fixed);
  fixed.surface_samples = model_.surface_samples;
  fixed.bodies = model_.bodies;
  fixed.colliders = model_.colliders;
  std::string bytes;
  StateArchive writer(bytes);
  writer(fixed, fixed.colliders);
  return hashOf(bytes.data(), bytes.size());
}

void World::restore(const WorldSnapshot& snapshot)
{
  if (snapshot.world_)
  {
    const std::string theirs = sceneSummary(snapshot.world_->model_), ours = sceneSummary(model_);
    if (theirs != ours)
      throw anotherScene(theirs, ours);
    *this = *snapshot.world_;
    return;
  }
  if (snapshot.fingerprint_ != fingerprint())
    throw anotherScene(snapshot.summary_, sceneSummary(model_));
  // Read into a copy, so that bytes that fail part way leave this world as it was.
  World next(*this);
  StateArchive reader(snapshot.bytes_->data() + snapshot.body_, snapshot.bytes_->size() - snapshot.body_);
  next.carry(reader);
  if (reader.left() != 0)
    throw std::invalid_argument("snapshot bytes: " + std::to_string(reader.left()) +
                                " more than this scene's values");
  // The bytes' elements carry their world's factors; what those multiply are this world's elements as built.
  next.material_.factorsRead(model_);
  next.integration_observer_ = std::move(integration_observer_);
  *this = std::move(next);
}

void World::carry(StateArchive& archive)
{
  archive(model_, state_, settings_);
  for (BodyController& controller : controllers_)
    controller.controller->carry(archive);
  archive(anchors_, grasps_, slips_);
  integrators_.carry(archive, model_);
  archive(contacts_, self_contacts_, material_, guard_, time_origin_, steps_origin_, steps_);
}

}  // namespace soft_body_sim
