#include "scene/body_readers.h"

namespace soft_body_sim::scene_yaml
{
const std::vector<BodyType>& bodyTypes()
{
  static const std::vector<BodyType> types = {
    { "custom", readCustomBody },
    { "rope", readRopeBody },
    { "rod", readRodBody },
    { "cloth", readClothBody },
    { "jelly", readJellyBody },
    { "volume", readVolumeBody },
    { "creature", readCreatureBody },
    { "limb", readLimbBody },
    { "humanoid", readHumanoidBody },
  };
  return types;
}

namespace
{
/// The value at a dotted key path ("tendrils.mass") below `map`, or nullopt. (Fields are made, never
/// assigned: assigning a YAML::Node overwrites the node it refers to.)
std::optional<Field> findKeyPath(const Field& map, const std::string& path)
{
  const std::size_t dot = path.find('.');
  std::optional<Field> head = map.node.IsMap() ? optionalKey(map, path.substr(0, dot)) : std::nullopt;
  if (!head || dot == std::string::npos)
    return head;
  return findKeyPath(*head, path.substr(dot + 1));
}
}  // namespace

Field firstPresent(const Field& map, const std::vector<std::string>& keys)
{
  for (const std::string& key : keys)
    if (std::optional<Field> at = findKeyPath(map, key))
      return *at;
  return map;
}

Keys withCommonBodyKeys(const Keys& own)
{
  Keys keys = { "name", "type" };
  keys.insert(keys.end(), own.begin(), own.end());
  keys.push_back("color");
  keys.push_back("anchors");
  return keys;
}

}  // namespace soft_body_sim::scene_yaml
