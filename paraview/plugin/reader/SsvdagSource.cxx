// VolumeSource of an .ssvdag file: vdbdag's public reader library.
#include "VolumeSource.h"

namespace
{
class SsvdagSource : public VolumeSource
{
public:
  explicit SsvdagSource(const std::string& path)
    : File(vdbdag::File::open(path))
  {
    for (size_t g = 0; g < this->File.gridCount(); ++g)
    {
      const vdbdag::Grid& grid = this->File.grid(g);
      this->Grids.push_back({ grid.name(), grid.valueType(), grid.valueSize(), grid.indexToWorld(), grid.indexBBox() });
    }
    if (this->File.isSequence())
      for (const vdbdag::Frame& f : this->File.frames())
        this->Frames.push_back({ f.number, f.firstGrid, f.gridCount });
  }
  void sample(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, void* out) const override
  {
    this->File.grid(g).sampleBox(box, stride, out);
  }
  void sampleActive(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, uint8_t* out) const override
  {
    this->File.grid(g).sampleActive(box, stride, out);
  }

  void forEachActive(size_t g, const vdbdag::IndexBBox& box, const vdbdag::Grid::ActiveVisitor& visit) const override
  {
    this->File.grid(g).forEachActive(box, visit);
  }

private:
  vdbdag::File File;
};
} // namespace

std::unique_ptr<VolumeSource> openSsvdagSource(const std::string& path)
{
  return std::make_unique<SsvdagSource>(path);
}
