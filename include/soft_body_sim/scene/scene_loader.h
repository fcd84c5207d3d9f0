// Reads scene files (YAML) into SceneDef. The one parser of the package: the headless simulator and
// the ROS node both load scenes through it, so they share one set of error messages.
#pragma once

#include <cstdint>
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

/// The largest scene file read [bytes]: 64 MiB, the largest scene the node limit allows written out in
/// YAML, with margin. Only a custom body's listed nodes make a file big (every other body type is a few
/// keys however many nodes it has), and kMaxSceneNodes of them, one `- {position: [0.125, -2.5, 1.75],
/// mass: 0.001}` each, take ~50 MB. A larger file is refused by its size before it is read.
constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t{ 64 } << 20;

/// Loads and validates a scene file; throws SceneError. The file must be a regular file (a FIFO, a
/// directory or a device is refused before it is opened) of at most kMaxSceneFileBytes, and the custom
/// bodies' `nodes` lists are counted against kMaxSceneNodes by a scan of the YAML events, before
/// yaml-cpp builds its tree of the document (~480 bytes a value: 70 times the text of a node list).
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
