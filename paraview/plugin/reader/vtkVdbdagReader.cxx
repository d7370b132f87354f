// vtkVdbdagReader (vtkVdbdagReader.h): the plan of an image (which grids, the
// box, the level) is made in RequestInformation from the files' grid facts
// alone; RequestData reads the update extent's point samples through a
// VolumeSource (VolumeSource.h), blocks of slices on every core.
#include "vtkVdbdagReader.h"

#include "ActiveCells.h"
#include "VolumeSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArraySelection.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

vtkStandardNewMacro(vtkVdbdagReader);

namespace
{
// A file kept open while it does not change on disk.
struct OpenFile
{
  std::unique_ptr<VolumeSource> Source;
  std::string Path;
  std::filesystem::file_time_type Time;
  std::uintmax_t Size = 0;

  // Opens `path` unless it is open and unchanged; true when (re)opened.
  bool Refresh(const std::string& path)
  {
    std::error_code ec;
    const auto time = std::filesystem::last_write_time(path, ec);
    const auto size = std::filesystem::file_size(path, ec);
    if (this->Source && this->Path == path && this->Time == time && this->Size == size)
      return false;
    this->Source.reset();
    this->Source = VolumeSource::open(path);
    this->Path = path;
    this->Time = time;
    this->Size = size;
    return true;
  }
};

// The world position of index (i, j, k): [i j k 1] * M, M row-major.
std::array<double, 3> WorldOf(const std::array<double, 16>& m, const std::array<int64_t, 3>& ijk)
{
  std::array<double, 3> w{};
  for (int r = 0; r < 3; ++r)
    w[r] = double(ijk[0]) * m[r] + double(ijk[1]) * m[4 + r] + double(ijk[2]) * m[8 + r] + m[12 + r];
  return w;
}

// Spacing (stride times each index axis's world length) and the direction
// matrix (row-major, column a the unit vector of index axis a).
void AxesOf(const std::array<double, 16>& m, uint64_t stride, double spacing[3], double direction[9])
{
  for (int a = 0; a < 3; ++a)
  {
    const double len = std::sqrt(m[4 * a] * m[4 * a] + m[4 * a + 1] * m[4 * a + 1] + m[4 * a + 2] * m[4 * a + 2]);
    spacing[a] = len * double(stride);
    for (int r = 0; r < 3; ++r)
      direction[3 * r + a] = len > 0 ? m[4 * a + r] / len : (r == a ? 1.0 : 0.0);
  }
}

// Reads component c of a value as a double; chosen once per grid by its type
// (a comparison reads two per component of every point).
using ComponentReader = double (*)(const uint8_t* value, int c);
template <typename T>
double ReadComponent(const uint8_t* value, int c)
{
  T v;
  std::memcpy(&v, value + size_t(c) * sizeof v, sizeof v);
  return double(v);
}
ComponentReader ComponentReaderFor(const std::string& type)
{
  if (type == "float" || type == "vec3s")
    return &ReadComponent<float>;
  if (type == "double" || type == "vec3d")
    return &ReadComponent<double>;
  if (type == "int32" || type == "vec3i")
    return &ReadComponent<int32_t>;
  if (type == "int64")
    return &ReadComponent<int64_t>;
  return &ReadComponent<uint8_t>; // bool, mask
}
} // namespace

struct vtkVdbdagReader::Internals
{
  OpenFile A, B;                  // the file, and the one it is compared with
  std::vector<std::string> Names; // the selection's name of each grid of A
  bool UpdatingSelection = false;

  // The plan of the last RequestInformation.
  std::vector<size_t> Grids;    // A's grids read, in file order
  std::vector<size_t> Partners; // with CompareWith: the grid of B of each
  // Of a sequence file, grids of its first frame; RequestData reads the
  // grids that stand for them in the frame of the time asked for (Current:
  // A's, CurrentPartners: B's; SIZE_MAX where the frame lacks one).
  std::vector<size_t> Current, CurrentPartners;
  vdbdag::IndexBBox Box;
  uint64_t Stride = 1;
  std::array<double, 16> IndexToWorld{};
  // The image this plan makes. RequestData sets them on the output itself:
  // a file series (vtkFileSeriesReader) plans each file in a temporary
  // information object, so the pipeline's keys keep the first file's.
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  double Origin[3] = { 0, 0, 0 }, Spacing[3] = { 1, 1, 1 }, Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
};

vtkVdbdagReader::vtkVdbdagReader()
  : GridSelection(vtkDataArraySelection::New())
  , SelectionObserver(vtkCallbackCommand::New())
  , Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SelectionObserver->SetCallback(&vtkVdbdagReader::SelectionModified);
  this->SelectionObserver->SetClientData(this);
  this->GridSelection->AddObserver(vtkCommand::ModifiedEvent, this->SelectionObserver);
}

vtkVdbdagReader::~vtkVdbdagReader()
{
  this->GridSelection->RemoveObserver(this->SelectionObserver);
  this->GridSelection->Delete();
  this->SelectionObserver->Delete();
  this->SetFileName(nullptr);
  this->SetCompareWith(nullptr);
}

void vtkVdbdagReader::SelectionModified(vtkObject*, unsigned long, void* clientdata, void*)
{
  auto* self = static_cast<vtkVdbdagReader*>(clientdata);
  if (!self->Internal->UpdatingSelection)
    self->Modified();
}

int vtkVdbdagReader::CanReadFile(const char* name)
{
  return VolumeSource::kindOf(name ? name : "") != VolumeSource::Kind::None ? 1 : 0;
}

vtkDataArraySelection* vtkVdbdagReader::GetGridSelection()
{
  return this->GridSelection;
}
int vtkVdbdagReader::GetNumberOfGridArrays()
{
  return this->GridSelection->GetNumberOfArrays();
}
const char* vtkVdbdagReader::GetGridArrayName(int index)
{
  return this->GridSelection->GetArrayName(index);
}
int vtkVdbdagReader::GetGridArrayStatus(const char* name)
{
  return this->GridSelection->ArrayIsEnabled(name);
}
void vtkVdbdagReader::SetGridArrayStatus(const char* name, int status)
{
  if (status)
    this->GridSelection->EnableArray(name);
  else
    this->GridSelection->DisableArray(name);
}

int vtkVdbdagReader::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int extent[6] = { 0, -1, 0, -1, 0, -1 }; // empty until the files are read
  if (this->OutputType == 0)
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro(<< "no file name");
    return 0;
  }
  try
  {
    const std::string path = this->FileName;
    if (in.A.Refresh(path))
    {
      // Selection names: the grid's name ("grid" when it has none), made
      // unique with " (2)", " (3)".
      std::vector<std::string> names;
      for (size_t i = 0; i < in.A.Source->firstFrameGrids(); ++i)
      {
        const VolumeGrid& g = in.A.Source->grids()[i];
        const std::string base = g.name.empty() ? "grid" : g.name;
        std::string name = base;
        for (int n = 2; std::find(names.begin(), names.end(), name) != names.end(); ++n)
          name = base + " (" + std::to_string(n) + ")";
        names.push_back(name);
      }
      if (names != in.Names)
      {
        in.UpdatingSelection = true;
        this->GridSelection->RemoveAllArrays();
        for (const std::string& name : names)
          this->GridSelection->AddArray(name.c_str());
        in.UpdatingSelection = false;
        in.Names = names;
      }
    }
    const bool compare = this->CompareWith && *this->CompareWith;
    if (compare)
      in.B.Refresh(this->CompareWith);
    else
      in.B.Source.reset();

    // Which grids: the selected ones that share the first one's transform
    // (and, when comparing, have a grid of the same name and type in B).
    const std::vector<VolumeGrid>& grids = in.A.Source->grids();
    in.Grids.clear();
    in.Partners.clear();
    for (size_t g = 0; g < in.A.Source->firstFrameGrids(); ++g)
    {
      if (!this->GridSelection->ArrayIsEnabled(in.Names[g].c_str()))
        continue;
      if (!in.Grids.empty() && grids[g].indexToWorld != in.IndexToWorld)
      {
        vtkWarningMacro(<< path << ": grid '" << in.Names[g] << "' has another transform than '" << in.Names[in.Grids[0]]
                        << "' and is left out (select it alone to read it)");
        continue;
      }
      if (compare)
      {
        const std::vector<VolumeGrid>& other = in.B.Source->grids();
        const auto end = other.begin() + long(in.B.Source->firstFrameGrids());
        const auto it = std::find_if(other.begin(), end, [&](const VolumeGrid& o) { return o.name == grids[g].name; });
        if (it == end || it->type != grids[g].type)
        {
          vtkWarningMacro(<< this->CompareWith << ": no " << grids[g].type << " grid named '" << grids[g].name
                          << "' to compare with; it is left out");
          continue;
        }
        in.Partners.push_back(size_t(it - other.begin()));
      }
      if (in.Grids.empty())
        in.IndexToWorld = grids[g].indexToWorld;
      in.Grids.push_back(g);
    }
    if (in.Grids.empty())
      in.IndexToWorld = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };

    // The box: the one asked for, or the union of the grids' active boxes
    // (of both files when comparing).
    in.Box = vdbdag::IndexBBox{};
    auto grow = [&](const vdbdag::IndexBBox& b) {
      if (b.empty())
        return;
      const bool first = in.Box.empty();
      for (int a = 0; a < 3; ++a)
      {
        in.Box.min[a] = first ? b.min[a] : std::min(in.Box.min[a], b.min[a]);
        in.Box.max[a] = first ? b.max[a] : std::max(in.Box.max[a], b.max[a]);
      }
    };
    if (this->UseBox)
    {
      for (int a = 0; a < 3; ++a)
      {
        in.Box.min[a] = this->Box[2 * a];
        in.Box.max[a] = this->Box[2 * a + 1];
      }
    }
    else
    {
      // (Of a sequence, every frame's: one image for all its time steps.)
      const size_t frames = std::max<size_t>(1, in.A.Source->frames().size());
      for (size_t f = 0; f < frames; ++f)
        for (size_t n = 0; n < in.Grids.size(); ++n)
          if (const size_t g = in.A.Source->gridInFrame(in.Grids[n], f); g != SIZE_MAX)
            grow(grids[g].box);
      if (compare)
        for (size_t f = 0; f < std::max<size_t>(1, in.B.Source->frames().size()); ++f)
          for (size_t n = 0; n < in.Grids.size(); ++n)
            if (const size_t g = in.B.Source->gridInFrame(in.Partners[n], f); g != SIZE_MAX)
              grow(in.B.Source->grids()[g].box);
    }

    // The level: as asked, or the finest within the budget.
    int level = this->LevelOfDetail;
    if (level < 0)
    {
      level = 0;
      while (level < 62 && double(vdbdag::sampleCount(in.Box, uint64_t(1) << level)) > this->MaximumCells * 1e6)
        ++level;
    }
    this->ChosenLevel = level;
    in.Stride = uint64_t(1) << level;
    const std::array<uint64_t, 3> dims = vdbdag::sampleDims(in.Box, in.Stride);
    vdbdag::sampleCount(in.Box, in.Stride); // refuses a count past 2^62
    if (!in.Box.empty() && !in.Grids.empty())
    {
      for (int a = 0; a < 3; ++a)
      {
        if (dims[a] > uint64_t(INT32_MAX))
        {
          vtkErrorMacro(<< path << ": " << dims[a] << " samples along an axis (choose a coarser level of detail)");
          return 0;
        }
        extent[2 * a + 1] = int(dims[a]) - 1;
      }
    }
    AxesOf(in.IndexToWorld, in.Stride, in.Spacing, in.Direction);
    const std::array<double, 3> origin = WorldOf(in.IndexToWorld, in.Box.empty() ? std::array<int64_t, 3>{ 0, 0, 0 } : in.Box.min);
    std::copy(origin.begin(), origin.end(), in.Origin);
    std::copy(extent, extent + 6, in.WholeExtent);
    // A sequence file's frames are its time steps, by frame number.
    if (!in.A.Source->frames().empty())
    {
      std::vector<double> steps;
      for (const VolumeFrame& f : in.A.Source->frames())
        steps.push_back(double(f.number));
      outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), steps.data(), int(steps.size()));
      const double range[2] = { steps.front(), steps.back() };
      outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    }
    else
    {
      outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
      outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
    }
    if (this->OutputType == 1) // cells: no extent
    {
      outInfo->Remove(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
      outInfo->Remove(CAN_PRODUCE_SUB_EXTENT());
      return 1;
    }
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
    outInfo->Set(vtkDataObject::ORIGIN(), in.Origin, 3);
    outInfo->Set(vtkDataObject::SPACING(), in.Spacing, 3);
    outInfo->Set(vtkDataObject::DIRECTION(), in.Direction, 9);
    outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
    return 1;
  }
  catch (const std::exception& e)
  {
    in.A.Source.reset();
    in.B.Source.reset();
    vtkErrorMacro(<< e.what());
    return 0;
  }
}

int vtkVdbdagReader::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject"); // RequestDataObject makes the one OutputType asks for
  return 1;
}

int vtkVdbdagReader::RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* out = vtkDataObject::GetData(outInfo);
  if (this->OutputType == 1 ? !vtkMultiBlockDataSet::SafeDownCast(out) : !vtkImageData::SafeDownCast(out))
  {
    vtkSmartPointer<vtkDataObject> made;
    if (this->OutputType == 1)
      made = vtkSmartPointer<vtkMultiBlockDataSet>::New();
    else
      made = vtkSmartPointer<vtkImageData>::New();
    outInfo->Set(vtkDataObject::DATA_OBJECT(), made);
  }
  return 1;
}

int vtkVdbdagReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  Internals& in = *this->Internal;
  if (!in.A.Source)
    return 0;
  // The frame of the time asked for (a sequence file), and B's of the same number.
  const std::vector<VolumeFrame>& frames = in.A.Source->frames();
  const double time = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    : (frames.empty() ? 0.0 : double(frames.front().number));
  const size_t frame = in.A.Source->frameAt(time);
  const double number = frames.empty() ? time : double(frames[frame].number);
  in.Current.clear();
  in.CurrentPartners.clear();
  for (size_t n = 0; n < in.Grids.size(); ++n)
  {
    in.Current.push_back(in.A.Source->gridInFrame(in.Grids[n], frame));
    if (in.B.Source)
      in.CurrentPartners.push_back(in.B.Source->gridInFrame(in.Partners[n], in.B.Source->frameAt(number)));
  }
  vtkDataObject* out = vtkDataObject::GetData(outInfo);
  if (out && !frames.empty())
    out->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), number);
  return this->OutputType == 1 ? this->RequestActiveCells(outInfo) : this->RequestImage(outInfo);
}

int vtkVdbdagReader::RequestActiveCells(vtkInformation* outInfo)
{
  Internals& in = *this->Internal;
  vtkMultiBlockDataSet* out = vtkMultiBlockDataSet::GetData(outInfo);
  if (!in.A.Source || !out)
    return 0;
  try
  {
    const uint64_t maxCells = uint64_t(this->MaximumCells * 1e6);
    std::vector<vtkSmartPointer<vtkUnstructuredGrid>> blocks; // all or none: a failure leaves the output empty
    for (size_t n = 0; n < in.Grids.size(); ++n)
    {
      const size_t g = in.Grids[n];
      if (in.Current[n] == SIZE_MAX) // not in this frame: an empty block
        blocks.push_back(vtkSmartPointer<vtkUnstructuredGrid>::New());
      else
        blocks.push_back(BuildActiveCells(*in.A.Source, in.Current[n], in.Box, in.Names[g], maxCells, in.A.Path));
      this->UpdateProgress(double(n + 1) / double(in.Grids.size()));
    }
    out->SetNumberOfBlocks(unsigned(blocks.size()));
    for (size_t n = 0; n < blocks.size(); ++n)
    {
      out->SetBlock(unsigned(n), blocks[n]);
      out->GetMetaData(unsigned(n))->Set(vtkCompositeDataSet::NAME(), in.Names[in.Grids[n]].c_str());
    }
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< in.A.Path << ": out of memory for the active cells (choose a Box)");
    return 0;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }
  return 1;
}

int vtkVdbdagReader::RequestImage(vtkInformation* outInfo)
{
  Internals& in = *this->Internal;
  vtkImageData* out = vtkImageData::GetData(outInfo);
  if (!in.A.Source || !out)
    return 0;
  // The update extent; a request for the pipeline's whole extent is one for
  // this plan's (they differ between the files of a series).
  int ext[6], whole[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext);
  outInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (std::equal(ext, ext + 6, whole))
    std::copy(in.WholeExtent, in.WholeExtent + 6, ext);
  for (int a = 0; a < 3; ++a)
  {
    ext[2 * a] = std::max(ext[2 * a], in.WholeExtent[2 * a]);
    ext[2 * a + 1] = std::min(ext[2 * a + 1], in.WholeExtent[2 * a + 1]);
  }
  out->SetExtent(ext);
  out->SetSpacing(in.Spacing);
  out->SetOrigin(in.Origin);
  out->SetDirectionMatrix(in.Direction);
  if (ext[1] < ext[0] || ext[3] < ext[2] || ext[5] < ext[4])
    return 1;

  // The update extent's voxels: box.min + ext * stride on each axis.
  const uint64_t nx = uint64_t(ext[1] - ext[0] + 1), ny = uint64_t(ext[3] - ext[2] + 1), nz = uint64_t(ext[5] - ext[4] + 1);
  const uint64_t slice = nx * ny;
  const vtkIdType points = vtkIdType(slice * nz);
  const int64_t stride = int64_t(in.Stride);
  const bool compare = in.B.Source != nullptr;
  const double work = double(in.Grids.size() * nz);
  double done = 0;
  // Runs read(zb, ze, slab) over slabs of 4 slices on every core, each
  // thread a contiguous block of slices (the value windows a block decodes
  // are mostly its own), while this thread reports progress. std::thread,
  // not vtkSMPTools: ParaView's default SMP backend is sequential. False
  // (and an error) when a read threw.
  auto forSlabs = [&](const std::function<void(uint64_t, uint64_t, const vdbdag::IndexBBox&)>& read) {
    const unsigned threads = unsigned(std::max<uint64_t>(1, std::min<uint64_t>(std::max(1u, std::thread::hardware_concurrency()), nz)));
    std::atomic<uint64_t> slices{ 0 };
    std::atomic<bool> stop{ false };
    std::mutex failed;
    std::string error;
    auto block = [&](unsigned t) {
      for (uint64_t z = nz * t / threads, end = nz * (t + 1) / threads; z < end && !stop; z += 4)
      {
        const uint64_t ze = std::min(end, z + 4);
        try
        {
          vdbdag::IndexBBox slab;
          for (int a = 0; a < 2; ++a)
          {
            slab.min[a] = in.Box.min[a] + int64_t(ext[2 * a]) * stride;
            slab.max[a] = in.Box.min[a] + int64_t(ext[2 * a + 1]) * stride;
          }
          slab.min[2] = in.Box.min[2] + (int64_t(ext[4]) + int64_t(z)) * stride;
          slab.max[2] = in.Box.min[2] + (int64_t(ext[4]) + int64_t(ze) - 1) * stride;
          read(z, ze, slab);
        }
        catch (const std::exception& e)
        {
          std::lock_guard<std::mutex> lock(failed);
          error = e.what();
          stop = true;
        }
        slices += ze - z;
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t)
      pool.emplace_back(block, t);
    while (slices < nz && !stop)
    {
      this->UpdateProgress((done + double(slices)) / work);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    for (std::thread& t : pool)
      t.join();
    done += double(nz);
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
      return false;
    }
    this->UpdateProgress(done / work);
    return true;
  };

  try
  {
    const std::vector<VolumeGrid>& grids = in.A.Source->grids();
    for (size_t n = 0; n < in.Grids.size(); ++n)
    {
      const size_t g = in.Grids[n];   // its name and type: the first frame's grid
      const size_t read = in.Current[n]; // the grid read: this frame's
      if (read == SIZE_MAX || (compare && in.CurrentPartners[n] == SIZE_MAX))
        continue; // not in this frame
      const VolumeGrid& grid = grids[g];
      const size_t row = std::max(1u, grid.valueSize);
      if (!compare)
      {
        vtkSmartPointer<vtkDataArray> values = ValueArray(grid, in.Names[g], points);
        auto* bytes = static_cast<uint8_t*>(values->GetVoidPointer(0));
        if (!forSlabs([&](uint64_t zb, uint64_t, const vdbdag::IndexBBox& slab) {
              in.A.Source->sample(read, slab, in.Stride, bytes + zb * slice * row);
            }))
          return 0;
        out->GetPointData()->AddArray(values);
        if (values->GetNumberOfComponents() == 1 && !out->GetPointData()->GetScalars())
          out->GetPointData()->SetActiveScalars(values->GetName());
        else if (values->GetNumberOfComponents() == 3 && !out->GetPointData()->GetVectors())
          out->GetPointData()->SetActiveVectors(values->GetName());
        continue;
      }
      // Compared with B's grid of the same name, as `vdbdag diff` does.
      const std::string prefix = in.Grids.size() > 1 ? in.Names[g] + " " : "";
      vtkSmartPointer<vtkDataArray> a = ValueArray(grid, prefix + "a", points), b = ValueArray(grid, prefix + "b", points);
      vtkNew<vtkDoubleArray> error;
      error->SetName((prefix + "abs_error").c_str());
      error->SetNumberOfTuples(points);
      vtkNew<vtkUnsignedCharArray> status;
      status->SetName((prefix + "status").c_str());
      status->SetNumberOfTuples(points);
      auto* aBytes = static_cast<uint8_t*>(a->GetVoidPointer(0));
      auto* bBytes = static_cast<uint8_t*>(b->GetVoidPointer(0));
      const int components = a->GetNumberOfComponents();
      const ComponentReader component = ComponentReaderFor(grid.type);
      if (!forSlabs([&](uint64_t zb, uint64_t ze, const vdbdag::IndexBBox& slab) {
            const uint64_t first = zb * slice, count = (ze - zb) * slice;
            in.A.Source->sample(read, slab, in.Stride, aBytes + first * row);
            in.B.Source->sample(in.CurrentPartners[n], slab, in.Stride, bBytes + first * row);
            std::vector<uint8_t> aOn(count), bOn(count);
            in.A.Source->sampleActive(read, slab, in.Stride, aOn.data());
            in.B.Source->sampleActive(in.CurrentPartners[n], slab, in.Stride, bOn.data());
            for (uint64_t p = 0; p < count; ++p)
            {
              const uint8_t* va = aBytes + (first + p) * row;
              const uint8_t* vb = bBytes + (first + p) * row;
              double sq = 0;
              for (int c = 0; c < components; ++c)
              {
                const double d = component(va, c) - component(vb, c);
                sq += d * d;
              }
              const bool same = std::memcmp(va, vb, row) == 0;
              error->SetValue(vtkIdType(first + p), same ? 0.0 : std::sqrt(sq));
              const uint8_t s = aOn[p] && bOn[p] ? (same ? 0 : 1) : aOn[p] ? 2 : bOn[p] ? 3 : 4;
              status->SetValue(vtkIdType(first + p), s);
            }
          }))
        return 0;
      out->GetPointData()->AddArray(a);
      out->GetPointData()->AddArray(b);
      out->GetPointData()->AddArray(error);
      out->GetPointData()->AddArray(status);
      if (!out->GetPointData()->GetScalars())
        out->GetPointData()->SetActiveScalars(error->GetName());
    }
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< in.A.Path << ": out of memory for " << points << " points (choose a coarser level of detail or a smaller box)");
    return 0;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }
  return 1;
}

void vtkVdbdagReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "CompareWith: " << (this->CompareWith ? this->CompareWith : "(none)") << "\n";
  os << indent << "OutputType: " << (this->OutputType == 1 ? "active voxels and tiles" : "image") << "\n";
  os << indent << "LevelOfDetail: " << this->LevelOfDetail << " (chosen " << this->ChosenLevel << ")\n";
  os << indent << "MaximumCells: " << this->MaximumCells << " million\n";
  os << indent << "UseBox: " << this->UseBox << " Box: " << this->Box[0] << " " << this->Box[1] << " " << this->Box[2] << " "
     << this->Box[3] << " " << this->Box[4] << " " << this->Box[5] << "\n";
}
