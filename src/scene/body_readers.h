// The readers of each body type. A reader gets a body mapping whose `type` it owns, checks the keys
// (its own plus the common ones: name, type, anchors) and returns the body expanded into nodes,
// springs and constraints (plus a controller for procedural bodies). The loader then fills in the
// name and type and reads the anchors, whose node indices refer to the expanded body.
#pragma once

#include <vector>

#include "yaml_reader.h"

namespace soft_body_sim::scene_yaml
{
using BodyReader = BodyDef (*)(const Context& ctx, const Field& body);

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

}  // namespace soft_body_sim::scene_yaml
