// The check every file a scene names (the scene itself, its meshes) passes before it is opened. A FIFO or
// a device would block the open or the read forever, a directory reads as nothing, and a file larger than
// its kind ever needs would be read whole into memory before any parser could refuse it.
#pragma once

#include <cstdint>
#include <string>

namespace soft_body_sim
{
/// Why the file at `path` must not be read, or "" if it may: it must exist and be a regular file (a
/// symbolic link is followed) of at most `max_bytes` bytes; `limit_name` names that limit in the reason
/// ("kMaxMeshFileBytes"). Looks only at the file's status (stat): never opens it, so it cannot block.
std::string unreadableFileReason(const std::string& path, std::uintmax_t max_bytes, const std::string& limit_name);

}  // namespace soft_body_sim
