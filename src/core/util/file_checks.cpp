#include "fdml_localization/core/util/file_checks.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace fdml_localization
{
namespace core
{
std::string regularFileProblem(const std::string& path)
{
  if (path.empty())
  {
    return "empty file name";
  }
  if (path.find('\0') != std::string::npos)
  {
    return "NUL byte in the file name";
  }
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
  {
    const int error = errno;
    if (error == ENOENT && ::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode))
    {
      return "a dangling symbolic link (its target does not exist)";
    }
    return error == ENOENT ? "no such file" : std::string("cannot access it: ") + std::strerror(error);
  }
  if (S_ISREG(st.st_mode))
  {
    return "";
  }
  const char* kind = S_ISDIR(st.st_mode)  ? "a directory" :
                     S_ISFIFO(st.st_mode) ? "a FIFO" :
                     S_ISSOCK(st.st_mode) ? "a socket" :
                     S_ISCHR(st.st_mode)  ? "a character device" :
                     S_ISBLK(st.st_mode)  ? "a block device" :
                                            "not a plain file";
  return std::string("not a regular file (") + kind + ")";
}

}  // namespace core
}  // namespace fdml_localization
