#include "fdml_localization/io/map_image.h"

#include "fdml_localization/core/map/polygon_map.h"

#include <stb/stb_image.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace fdml_localization
{
namespace io
{
using core::MapError;

namespace
{
std::string namedBy(const std::string& named_by)
{
  return named_by.empty() ? "" : " (named by " + named_by + ")";
}

/// A regular file opened read-only and non-blocking (checked before and after opening, so a
/// FIFO or a device is never waited on); closed on destruction.
class ImageFile
{
public:
  ImageFile(const std::string& path, const std::string& named_by)
  {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0)
    {
      throw MapError(path, 0,
                     (errno == ENOENT ? std::string("image file not found") :
                                        "cannot read the image: " + std::string(std::strerror(errno))) +
                         namedBy(named_by));
    }
    if (!S_ISREG(st.st_mode))
    {
      throw MapError(path, 0, "the image is not a regular file (a directory, FIFO or device)" + namedBy(named_by));
    }
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0 || ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    {
      const std::string why = fd < 0 ? std::strerror(errno) : "not a regular file";
      if (fd >= 0)
      {
        ::close(fd);
      }
      throw MapError(path, 0, "cannot open the image: " + why + namedBy(named_by));
    }
    size_ = static_cast<long long>(st.st_size);
    file_ = ::fdopen(fd, "rb");
    if (file_ == nullptr)
    {
      ::close(fd);
      throw MapError(path, 0, "cannot open the image" + namedBy(named_by));
    }
  }
  ~ImageFile()
  {
    std::fclose(file_);
  }
  ImageFile(const ImageFile&) = delete;
  ImageFile& operator=(const ImageFile&) = delete;

  FILE* get() const
  {
    return file_;
  }
  long long size() const
  {
    return size_;
  }

private:
  FILE* file_ = nullptr;
  long long size_ = 0;
};

/// Reads the next header number of a binary PNM (after blanks and '#' comments); -1 if none.
long long pnmNumber(const std::string& header, std::size_t& pos)
{
  while (pos < header.size() && (std::isspace(static_cast<unsigned char>(header[pos])) || header[pos] == '#'))
  {
    if (header[pos] == '#')
    {
      pos = header.find_first_of("\r\n", pos);
      pos = pos == std::string::npos ? header.size() : pos;
    }
    else
    {
      ++pos;
    }
  }
  long long value = -1;
  while (pos < header.size() && std::isdigit(static_cast<unsigned char>(header[pos])) && value < 1000000000LL)
  {
    value = (value < 0 ? 0 : 10 * value) + (header[pos++] - '0');
  }
  return value;
}

/// A binary PGM/PPM must hold every pixel byte its header announces.
void checkPnmLength(const ImageFile& file, const ImageInfo& info, const std::string& path, const std::string& named_by)
{
  std::string header(4096, '\0');
  std::rewind(file.get());
  header.resize(std::fread(&header[0], 1, header.size(), file.get()));
  std::rewind(file.get());
  if (header.size() < 2 || header[0] != 'P' || (header[1] != '5' && header[1] != '6'))
  {
    return;
  }
  std::size_t pos = 2;
  const long long width = pnmNumber(header, pos);
  const long long height = pnmNumber(header, pos);
  const long long maxval = pnmNumber(header, pos);
  if (width != info.width || height != info.height || maxval <= 0 || pos >= header.size())
  {
    throw MapError(path, 0, "malformed PGM/PPM header" + namedBy(named_by));
  }
  ++pos;  // the single blank after maxval
  const long long needed = width * height * info.channels * (maxval > 255 ? 2 : 1);
  const long long present = file.size() - static_cast<long long>(pos);
  if (present < needed)
  {
    throw MapError(path, 0,
                   "truncated image: " + std::to_string(present) + " bytes of pixel data where its header (" +
                       std::to_string(width) + " x " + std::to_string(height) + ", maxval " + std::to_string(maxval) +
                       ") needs " + std::to_string(needed) + namedBy(named_by));
  }
}

ImageInfo checkImage(const ImageFile& file, const std::string& path, const std::string& named_by)
{
  ImageInfo info;
  if (!stbi_info_from_file(file.get(), &info.width, &info.height, &info.channels))
  {
    const char* why = stbi_failure_reason();
    throw MapError(path, 0,
                   std::string("cannot decode the image header (") + (why ? why : "unknown reason") +
                       "; readable: binary PGM, PNG, BMP, JPEG, TGA, GIF)" + namedBy(named_by));
  }
  const long long cells = static_cast<long long>(info.width) * static_cast<long long>(info.height);
  if (info.width < 1 || info.height < 1 || info.width > kMaxGridSide || info.height > kMaxGridSide ||
      cells > kMaxGridCells)
  {
    throw MapError(path, 0,
                   "image of " + std::to_string(info.width) + " x " + std::to_string(info.height) +
                       " pixels is beyond the limit (each side 1 to " + std::to_string(kMaxGridSide) + ", at most " +
                       std::to_string(kMaxGridCells / 1000000) + " M cells; see docs/maps_occupancy.md)" +
                       namedBy(named_by));
  }
  checkPnmLength(file, info, path, named_by);
  return info;
}
}  // namespace

ImageInfo readImageInfo(const std::string& path, const std::string& named_by)
{
  const ImageFile file(path, named_by);
  return checkImage(file, path, named_by);
}

std::vector<std::uint8_t> loadImagePixels(const std::string& path, ImageInfo& info, const std::string& named_by)
{
  const ImageFile file(path, named_by);
  info = checkImage(file, path, named_by);
  int width = 0;
  int height = 0;
  int channels = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load_from_file(file.get(), &width, &height, &channels, 0),
                                                   stbi_image_free);
  if (!pixels || width != info.width || height != info.height || channels != info.channels)
  {
    const char* why = pixels ? "size differs from its header" : stbi_failure_reason();
    throw MapError(path, 0,
                   std::string("cannot decode the image (") + (why ? why : "unknown reason") + ")" + namedBy(named_by));
  }
  const std::size_t bytes =
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels);
  return std::vector<std::uint8_t>(pixels.get(), pixels.get() + bytes);
}

}  // namespace io
}  // namespace fdml_localization
