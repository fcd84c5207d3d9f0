#include "body_readers.h"

namespace soft_body_sim::scene_yaml
{
const std::vector<BodyType>& bodyTypes()
{
  static const std::vector<BodyType> types = {
    { "custom", readCustomBody },
    { "rope", readRopeBody },
    { "cloth", readClothBody },
    { "jelly", readJellyBody },
    { "creature", readCreatureBody },
    { "limb", readLimbBody },
    { "humanoid", readHumanoidBody },
  };
  return types;
}

Keys withCommonBodyKeys(const Keys& own)
{
  Keys keys = { "name", "type" };
  keys.insert(keys.end(), own.begin(), own.end());
  keys.push_back("anchors");
  return keys;
}

}  // namespace soft_body_sim::scene_yaml
