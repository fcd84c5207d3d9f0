// The error of a definition (a body, a collider) that its builder or check rejects, naming the keys it
// is about, so that the scene loader can point at the one a file sets.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace soft_body_sim
{
/// A definition that its builder rejects (buildRope, buildCreature, ...): what is wrong, and the keys of
/// the definition it is about, in the order a reader should point at them (the scene loader reports it at
/// the first of them that the file sets). Each check lives in the builder only; readers only parse.
class DefinitionError : public std::invalid_argument
{
public:
  DefinitionError(const std::string& what, std::vector<std::string> keys)
    : std::invalid_argument(what), keys_(std::move(keys))
  {
  }
  const std::vector<std::string>& keys() const noexcept { return keys_; }

private:
  std::vector<std::string> keys_;
};

/// Throws DefinitionError(subject + ": " + reason, keys) unless `ok`; `subject` names the definition,
/// such as "rope 'cable'".
inline void requireDefinition(bool ok, const std::string& subject, std::vector<std::string> keys,
                              const std::string& reason)
{
  if (!ok)
    throw DefinitionError(subject + ": " + reason, std::move(keys));
}

}  // namespace soft_body_sim
