#include "VolumeSource.h"

#include <cstdint>
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

size_t VolumeSource::gridInFrame(size_t g, size_t frame) const
{
  if (this->Frames.empty())
    return g;
  const VolumeGrid& want = this->Grids[g];
  size_t k = 0; // grids of that name before g in the first frame
  for (size_t i = 0; i < g; ++i)
    k += this->Grids[i].name == want.name ? 1 : 0;
  const VolumeFrame& f = this->Frames[frame];
  for (size_t i = f.firstGrid; i < f.firstGrid + f.gridCount; ++i)
    if (this->Grids[i].name == want.name && k-- == 0)
      return this->Grids[i].type == want.type ? i : SIZE_MAX;
  return SIZE_MAX;
}

size_t VolumeSource::frameAt(double time) const
{
  size_t f = 0;
  for (size_t i = 1; i < this->Frames.size(); ++i)
    if (double(this->Frames[i].number) <= time)
      f = i;
  return f;
}
