#include "VolumeSource.h"

#include <cstring>
#include <fstream>
#include <stdexcept>

VolumeSource::Kind VolumeSource::kindOf(const std::string& path)
{
  static const char ssvdag[8] = { '\x89', 'S', 'S', 'V', 'D', 'A', 'G', '\n' };
  static const char vdb[4] = { ' ', 'B', 'D', 'V' }; // OpenVDB's magic 0x56444220, little-endian
  char head[8] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in.read(head, 8))
    return Kind::None;
  return std::memcmp(head, ssvdag, 8) == 0 ? Kind::Ssvdag : std::memcmp(head, vdb, 4) == 0 ? Kind::Vdb : Kind::None;
}

std::unique_ptr<VolumeSource> VolumeSource::open(const std::string& path)
{
  if (!std::ifstream(path, std::ios::binary))
    throw std::runtime_error(path + ": cannot open the file");
  // Anything but an .ssvdag goes to OpenVDB's checked reader, which names what is wrong.
  return kindOf(path) == Kind::Ssvdag ? openSsvdagSource(path) : openVdbSource(path);
}
