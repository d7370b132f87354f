#include "VolumeSource.h"

#include <cstring>
#include <fstream>

std::unique_ptr<VolumeSource> VolumeSource::open(const std::string& path)
{
  static const char magic[8] = { '\x89', 'S', 'S', 'V', 'D', 'A', 'G', '\n' };
  char head[8] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw std::runtime_error(path + ": cannot open the file");
  if (in.read(head, 8) && std::memcmp(head, magic, 8) == 0)
    return openSsvdagSource(path);
  return openVdbSource(path);
}
