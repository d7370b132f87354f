// A volume file as the reader plugin sees it: its grids' facts, and point
// samples of a box of index coordinates every `stride` voxels, laid out as
// vdbdag::Grid::sampleBox writes them (i fastest; a mask grid's samples are
// its active states, one byte each; bool one byte). Two kinds:
// .ssvdag through vdbdag's reader library (SsvdagSource.cxx) and .vdb through
// OpenVDB's own reader with delayed loading (VdbSource.cxx), so a coarse
// level of detail reads only the leaves its samples fall in.
#ifndef VolumeSource_h
#define VolumeSource_h

#include <vdbdag/vdbdag.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct VolumeGrid
{
  std::string name;  // as the file names it
  std::string type;  // "float", "double", "int32", "int64", "bool", "mask", "vec3s", "vec3d", "vec3i"
  unsigned valueSize = 0; // bytes per value (mask 0: its samples are one byte)
  std::array<double, 16> indexToWorld{}; // row-major, world = [i j k 1] * M
  vdbdag::IndexBBox box; // of the active voxels
};

// A frame of a sequence file (vdbdag::File::frames): its grids are
// grids()[firstGrid, firstGrid + gridCount).
struct VolumeFrame
{
  int64_t number = 0;
  size_t firstGrid = 0, gridCount = 0;
};

class VolumeSource
{
public:
  virtual ~VolumeSource() = default;
  const std::vector<VolumeGrid>& grids() const { return this->Grids; }
  // A sequence file's frames; empty for a file of one volume.
  const std::vector<VolumeFrame>& frames() const { return this->Frames; }
  // The grids of the first frame (every grid of a file of one volume).
  size_t firstFrameGrids() const { return this->Frames.empty() ? this->Grids.size() : this->Frames.front().gridCount; }
  // The grid of frame `frame` that stands for grid g of the first frame: the
  // same name and type, the k-th of that name when names repeat; g itself
  // for a file of one volume; SIZE_MAX when the frame has none.
  size_t gridInFrame(size_t g, size_t frame) const;
  // The frame shown at time `time`: the last whose number is <= time (the
  // first before them all); 0 for a file of one volume.
  size_t frameAt(double time) const;
  // Grid g's values at box.min + n * stride; callable from several threads
  // at once for disjoint outputs.
  virtual void sample(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, void* out) const = 0;
  // Their active states, one byte each (1: active).
  virtual void sampleActive(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, uint8_t* out) const = 0;
  // Grid g's active voxels and tiles that overlap the box, as
  // vdbdag::Grid::forEachActive gives them (a mask grid's value: nullptr;
  // a bool's: one byte).
  virtual void forEachActive(size_t g, const vdbdag::IndexBBox& box, const vdbdag::Grid::ActiveVisitor& visit) const = 0;
  // What a file is, by its first bytes: .ssvdag's magic, or OpenVDB's.
  enum class Kind { None, Ssvdag, Vdb };
  static Kind kindOf(const std::string& path);
  // Opens an .ssvdag file (by its magic) or else a .vdb file; throws
  // std::runtime_error with one line naming the file.
  static std::unique_ptr<VolumeSource> open(const std::string& path);

protected:
  std::vector<VolumeGrid> Grids;
  std::vector<VolumeFrame> Frames;
};

std::unique_ptr<VolumeSource> openSsvdagSource(const std::string& path);
std::unique_ptr<VolumeSource> openVdbSource(const std::string& path);

#endif
