// Scene-file names of the core's enums (integrators, guard policies): one lookup for all of them.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace soft_body_sim
{
/// Sets `value` to the enum value whose name `name` is, where `names` lists an enum's names in the
/// order of its values (0, 1, 2, ...); false, and `value` unchanged, if no name matches.
template <typename Enum>
bool enumFromName(const std::vector<std::string>& names, const std::string& name, Enum& value)
{
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name)
    {
      value = static_cast<Enum>(k);
      return true;
    }
  return false;
}

}  // namespace soft_body_sim
