#include "soft_body_sim/core/input_file.h"

#include <filesystem>
#include <system_error>

namespace soft_body_sim
{
std::string unreadableFileReason(const std::string& path, std::uintmax_t max_bytes, const std::string& limit_name)
{
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  switch (status.type())
  {
    case fs::file_type::regular:
      break;
    case fs::file_type::not_found:
      return "no such file";
    case fs::file_type::directory:
      return "it is a directory, not a regular file";
    case fs::file_type::fifo:
      return "it is a FIFO (named pipe), not a regular file";
    case fs::file_type::block:
    case fs::file_type::character:
      return "it is a device, not a regular file";
    case fs::file_type::socket:
      return "it is a socket, not a regular file";
    case fs::file_type::none:  // stat failed for another reason, such as a folder on the path we may not search
      return error.message();
    default:
      return "it is not a regular file";
  }
  const std::uintmax_t bytes = fs::file_size(path, error);
  if (error)
    return error.message();
  if (bytes > max_bytes)
    return "it is " + std::to_string(bytes) + " bytes, more than the " + std::to_string(max_bytes) +
           " such a file may have (" + limit_name + ")";
  return "";
}

}  // namespace soft_body_sim
