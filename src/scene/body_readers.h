// The readers of each body type. A reader gets a body mapping whose `type` it owns, checks the keys
// (its own plus the common ones: name, type, anchors) and returns the body expanded into nodes,
// springs and constraints (plus a controller for procedural bodies). The loader then fills in the
// name and type and reads the anchors, whose node indices refer to the expanded body.
#pragma once

#include <vector>

#include "yaml_reader.h"

namespace soft_body_sim
{
struct LimbMotion;
}

namespace soft_body_sim::scene_yaml
{
using BodyReader = BodyDef (*)(const Context& ctx, const Field& body);

/// The most nodes a scene may have, in all its bodies: a typo such as `nx: 100000` or
/// `segments: 1e9` fails with a message rather than exhausting memory.
constexpr long long kMaxSceneNodes = 1000000;

struct BodyType
{
  const char* name;
  BodyReader read;
};

/// Every body type a scene may use.
const std::vector<BodyType>& bodyTypes();

/// The keys every body type allows around its own: name, type, <own...>, anchors.
Keys withCommonBodyKeys(const Keys& own);

BodyDef readCustomBody(const Context& ctx, const Field& body);
BodyDef readRopeBody(const Context& ctx, const Field& body);
BodyDef readClothBody(const Context& ctx, const Field& body);
BodyDef readJellyBody(const Context& ctx, const Field& body);

// Procedurally animated body types (creature, limb, humanoid).
BodyDef readCreatureBody(const Context& ctx, const Field& body);
BodyDef readLimbBody(const Context& ctx, const Field& body);
BodyDef readHumanoidBody(const Context& ctx, const Field& body);
/// The limb-motion keys that `limb` and `humanoid` share (limb_reader.cpp): gravity, frame_period,
/// max_frames_per_step, iterations, tension, retention, curve_samples.
const Keys& limbMotionKeys();
/// Reads the limbMotionKeys() present in `body` (a mapping checked by requireMap) into `motion`.
void readLimbMotion(const Context& ctx, const Field& body, LimbMotion& motion);

}  // namespace soft_body_sim::scene_yaml
