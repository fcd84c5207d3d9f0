// Reads scene files (YAML) into SceneDef. The one parser of the package: the headless simulator and
// the ROS node both load scenes through it, so they share one set of error messages.
#pragma once

#include <stdexcept>
#include <string>

#include "soft_body_sim/core/meshing/volume_mesh.h"
#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// A scene that cannot be loaded. what() is one line: "<source>:<line>: <key>: <reason>".
class SceneError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Loads and validates a scene file; throws SceneError.
SceneDef loadSceneFile(const std::string& path);

/// What a scene may ask for beyond the fixed limits (kMaxSceneNodes), refused at the key that asks.
struct SceneLimits
{
  /// The most tetrahedra a volume's mesh may be asked for (volume_mesh.h). Meshing takes seconds per
  /// 10^5 tetrahedra, so a caller that must answer quickly (the fuzzer) lowers it.
  double tetrahedra = kMaxTetrahedra;
};

/// Parses and validates YAML text; `source` names it in error messages (a file path, "<string>").
SceneDef parseScene(const std::string& yaml_text, const std::string& source, const SceneLimits& limits = {});

}  // namespace soft_body_sim
