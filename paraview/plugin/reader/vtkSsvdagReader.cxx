// vtkSsvdagReader (vtkSsvdagReader.h): the plan of an image (which grids, the
// box, the level) is made in RequestInformation from the file's grid facts
// alone; RequestData reads the update extent's point samples with
// vdbdag::Grid::sampleBox, slabs of slices in parallel (vtkSMPTools), one
// accessor per slab.
#include "vtkSsvdagReader.h"

#include "vtkCallbackCommand.h"
#include "vtkDataArraySelection.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"

#include <vdbdag/vdbdag.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <new>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkSsvdagReader);

struct vtkSsvdagReader::Internals
{
  // The open file, and what it was opened as (a changed file is read again).
  std::unique_ptr<vdbdag::File> File;
  std::string Path;
  std::filesystem::file_time_type Time;
  std::uintmax_t Size = 0;
  std::vector<std::string> Names; // the selection's name of each grid
  bool UpdatingSelection = false;

  // The plan of the last RequestInformation.
  std::vector<size_t> Grids; // the grids read, in file order
  vdbdag::IndexBBox Box;
  uint64_t Stride = 1;
  std::array<uint64_t, 3> Dims{ 0, 0, 0 };
  std::array<double, 16> IndexToWorld{};
};

namespace
{
// The world position of index (i, j, k): [i j k 1] * M, M row-major.
std::array<double, 3> worldOf(const std::array<double, 16>& m, const std::array<double, 3>& ijk)
{
  std::array<double, 3> w{};
  for (int r = 0; r < 3; ++r)
  {
    w[r] = ijk[0] * m[r] + ijk[1] * m[4 + r] + ijk[2] * m[8 + r] + m[12 + r];
  }
  return w;
}

// Spacing (stride times each index axis's world length) and the direction
// matrix (row-major, column a the unit vector of index axis a).
void axesOf(const std::array<double, 16>& m, uint64_t stride, double spacing[3], double direction[9])
{
  for (int a = 0; a < 3; ++a)
  {
    const double len = std::sqrt(m[4 * a] * m[4 * a] + m[4 * a + 1] * m[4 * a + 1] + m[4 * a + 2] * m[4 * a + 2]);
    spacing[a] = len * double(stride);
    for (int r = 0; r < 3; ++r)
    {
      direction[3 * r + a] = len > 0 ? m[4 * a + r] / len : (r == a ? 1.0 : 0.0);
    }
  }
}

vtkSmartPointer<vtkDataArray> arrayFor(const std::string& type)
{
  vtkSmartPointer<vtkDataArray> array;
  if (type == "float" || type == "vec3s")
    array = vtkSmartPointer<vtkFloatArray>::New();
  else if (type == "double" || type == "vec3d")
    array = vtkSmartPointer<vtkDoubleArray>::New();
  else if (type == "int32" || type == "vec3i")
    array = vtkSmartPointer<vtkTypeInt32Array>::New();
  else if (type == "int64")
    array = vtkSmartPointer<vtkTypeInt64Array>::New();
  else // "bool" (one byte), "mask" (the active state)
    array = vtkSmartPointer<vtkUnsignedCharArray>::New();
  array->SetNumberOfComponents(type.rfind("vec3", 0) == 0 ? 3 : 1);
  return array;
}
} // namespace

vtkSsvdagReader::vtkSsvdagReader()
  : GridSelection(vtkDataArraySelection::New())
  , SelectionObserver(vtkCallbackCommand::New())
  , Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SelectionObserver->SetCallback(&vtkSsvdagReader::SelectionModified);
  this->SelectionObserver->SetClientData(this);
  this->GridSelection->AddObserver(vtkCommand::ModifiedEvent, this->SelectionObserver);
}

vtkSsvdagReader::~vtkSsvdagReader()
{
  this->GridSelection->RemoveObserver(this->SelectionObserver);
  this->GridSelection->Delete();
  this->SelectionObserver->Delete();
  this->SetFileName(nullptr);
}

void vtkSsvdagReader::SelectionModified(vtkObject*, unsigned long, void* clientdata, void*)
{
  auto* self = static_cast<vtkSsvdagReader*>(clientdata);
  if (!self->Internal->UpdatingSelection)
  {
    self->Modified();
  }
}

int vtkSsvdagReader::CanReadFile(const char* name)
{
  static const char magic[8] = { '\x89', 'S', 'S', 'V', 'D', 'A', 'G', '\n' };
  char head[8] = {};
  std::ifstream in(name ? name : "", std::ios::binary);
  return in.read(head, 8) && std::memcmp(head, magic, 8) == 0 ? 1 : 0;
}

vtkDataArraySelection* vtkSsvdagReader::GetGridSelection()
{
  return this->GridSelection;
}
int vtkSsvdagReader::GetNumberOfGridArrays()
{
  return this->GridSelection->GetNumberOfArrays();
}
const char* vtkSsvdagReader::GetGridArrayName(int index)
{
  return this->GridSelection->GetArrayName(index);
}
int vtkSsvdagReader::GetGridArrayStatus(const char* name)
{
  return this->GridSelection->ArrayIsEnabled(name);
}
void vtkSsvdagReader::SetGridArrayStatus(const char* name, int status)
{
  if (status)
    this->GridSelection->EnableArray(name);
  else
    this->GridSelection->DisableArray(name);
}

int vtkSsvdagReader::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int extent[6] = { 0, -1, 0, -1, 0, -1 }; // empty until the file is read
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro(<< "no file name");
    return 0;
  }
  try
  {
    const std::string path = this->FileName;
    std::error_code ec;
    const auto time = std::filesystem::last_write_time(path, ec);
    const auto size = std::filesystem::file_size(path, ec);
    if (!in.File || in.Path != path || in.Time != time || in.Size != size)
    {
      in.File.reset();
      in.File = std::make_unique<vdbdag::File>(vdbdag::File::open(path));
      in.Path = path;
      in.Time = time;
      in.Size = size;
      // Selection names: the grid's name, made unique with " (2)", " (3)".
      std::vector<std::string> names;
      for (size_t g = 0; g < in.File->gridCount(); ++g)
      {
        std::string name = in.File->grid(g).name().empty() ? "grid" : in.File->grid(g).name();
        for (int n = 2; std::find(names.begin(), names.end(), name) != names.end(); ++n)
        {
          name = in.File->grid(g).name() + " (" + std::to_string(n) + ")";
        }
        names.push_back(name);
      }
      if (names != in.Names)
      {
        in.UpdatingSelection = true;
        this->GridSelection->RemoveAllArrays();
        for (const std::string& name : names)
        {
          this->GridSelection->AddArray(name.c_str());
        }
        in.UpdatingSelection = false;
        in.Names = names;
      }
    }

    // Which grids: the selected ones that share the first one's transform.
    in.Grids.clear();
    for (size_t g = 0; g < in.Names.size(); ++g)
    {
      if (!this->GridSelection->ArrayIsEnabled(in.Names[g].c_str()))
        continue;
      const vdbdag::Grid& grid = in.File->grid(g);
      if (!in.Grids.empty() && grid.indexToWorld() != in.IndexToWorld)
      {
        vtkWarningMacro(<< path << ": grid '" << in.Names[g] << "' has another transform than '" << in.Names[in.Grids[0]]
                        << "' and is left out (select it alone to read it)");
        continue;
      }
      if (in.Grids.empty())
        in.IndexToWorld = grid.indexToWorld();
      in.Grids.push_back(g);
    }

    if (in.Grids.empty())
      in.IndexToWorld = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };

    // The box: the one asked for, or the union of the grids' active boxes.
    in.Box = vdbdag::IndexBBox{};
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
      for (const size_t g : in.Grids)
      {
        const vdbdag::IndexBBox b = in.File->grid(g).indexBBox();
        if (b.empty())
          continue;
        for (int a = 0; a < 3; ++a)
        {
          in.Box.min[a] = in.Box.empty() ? b.min[a] : std::min(in.Box.min[a], b.min[a]);
          in.Box.max[a] = in.Box.empty() ? b.max[a] : std::max(in.Box.max[a], b.max[a]);
        }
      }
    }

    // The level: as asked, or the finest within the budget.
    int level = this->LevelOfDetail;
    if (level < 0)
    {
      const double budget = this->MaximumCells * 1e6;
      level = 0;
      while (level < 62 && double(vdbdag::sampleCount(in.Box, uint64_t(1) << level)) > budget)
        ++level;
    }
    this->ChosenLevel = level;
    in.Stride = uint64_t(1) << level;
    in.Dims = vdbdag::sampleDims(in.Box, in.Stride);
    vdbdag::sampleCount(in.Box, in.Stride); // refuses a count past 2^62

    if (!in.Box.empty() && !in.Grids.empty())
    {
      for (int a = 0; a < 3; ++a)
      {
        if (in.Dims[a] > uint64_t(INT32_MAX))
        {
          vtkErrorMacro(<< path << ": " << in.Dims[a] << " samples along an axis (choose a coarser level of detail)");
          return 0;
        }
        extent[2 * a + 1] = int(in.Dims[a]) - 1;
      }
    }
    double spacing[3], direction[9];
    axesOf(in.IndexToWorld, in.Stride, spacing, direction);
    const std::array<int64_t, 3> corner = in.Box.empty() ? std::array<int64_t, 3>{ 0, 0, 0 } : in.Box.min;
    const std::array<double, 3> origin = worldOf(in.IndexToWorld, { double(corner[0]), double(corner[1]), double(corner[2]) });
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
    outInfo->Set(vtkDataObject::ORIGIN(), origin.data(), 3);
    outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
    outInfo->Set(vtkDataObject::DIRECTION(), direction, 9);
    outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
    return 1;
  }
  catch (const std::exception& e)
  {
    in.File.reset();
    vtkErrorMacro(<< e.what());
    return 0;
  }
}

int vtkSsvdagReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* out = vtkImageData::GetData(outInfo);
  if (!in.File || !out)
    return 0;
  int ext[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext);
  out->SetExtent(ext);
  double spacing[3], direction[9], origin[3];
  outInfo->Get(vtkDataObject::SPACING(), spacing);
  outInfo->Get(vtkDataObject::ORIGIN(), origin);
  outInfo->Get(vtkDataObject::DIRECTION(), direction);
  out->SetSpacing(spacing);
  out->SetOrigin(origin);
  out->SetDirectionMatrix(direction);
  if (ext[1] < ext[0] || ext[3] < ext[2] || ext[5] < ext[4])
    return 1;

  // The update extent's voxels: box.min + ext * stride on each axis.
  const uint64_t nx = uint64_t(ext[1] - ext[0] + 1), ny = uint64_t(ext[3] - ext[2] + 1), nz = uint64_t(ext[5] - ext[4] + 1);
  const vtkIdType points = vtkIdType(nx * ny * nz);
  const int64_t stride = int64_t(in.Stride);
  try
  {
    bool scalarsSet = false, vectorsSet = false;
    const uint64_t slabsPerStep = 16; // slices between progress reports
    const double work = double(in.Grids.size() * nz);
    double done = 0;
    for (const size_t g : in.Grids)
    {
      const vdbdag::Grid& grid = in.File->grid(g);
      vtkSmartPointer<vtkDataArray> array = arrayFor(grid.valueType());
      array->SetName(in.Names[g].c_str());
      array->SetNumberOfTuples(points);
      const size_t row = std::max(1u, grid.valueSize());
      auto* bytes = static_cast<uint8_t*>(array->GetVoidPointer(0));
      std::mutex failed;
      std::string error;
      for (uint64_t z0 = 0; z0 < nz; z0 += slabsPerStep)
      {
        const uint64_t z1 = std::min(nz, z0 + slabsPerStep);
        vtkSMPTools::For(vtkIdType(z0), vtkIdType(z1), 1, [&](vtkIdType zb, vtkIdType ze) {
          try
          {
            vdbdag::IndexBBox slab;
            for (int a = 0; a < 2; ++a)
            {
              slab.min[a] = in.Box.min[a] + int64_t(ext[2 * a]) * stride;
              slab.max[a] = in.Box.min[a] + int64_t(ext[2 * a + 1]) * stride;
            }
            slab.min[2] = in.Box.min[2] + (int64_t(ext[4]) + zb) * stride;
            slab.max[2] = in.Box.min[2] + (int64_t(ext[4]) + ze - 1) * stride;
            grid.sampleBox(slab, in.Stride, bytes + uint64_t(zb) * nx * ny * row);
          }
          catch (const std::exception& e)
          {
            std::lock_guard<std::mutex> lock(failed);
            error = e.what();
          }
        });
        if (!error.empty())
        {
          vtkErrorMacro(<< error);
          return 0;
        }
        done += double(z1 - z0);
        this->UpdateProgress(done / work);
      }
      out->GetPointData()->AddArray(array);
      if (array->GetNumberOfComponents() == 1 && !scalarsSet)
      {
        out->GetPointData()->SetActiveScalars(array->GetName());
        scalarsSet = true;
      }
      else if (array->GetNumberOfComponents() == 3 && !vectorsSet)
      {
        out->GetPointData()->SetActiveVectors(array->GetName());
        vectorsSet = true;
      }
    }
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< in.Path << ": out of memory for " << points << " points (choose a coarser level of detail or a smaller box)");
    return 0;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }
  return 1;
}

void vtkSsvdagReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "LevelOfDetail: " << this->LevelOfDetail << " (chosen " << this->ChosenLevel << ")\n";
  os << indent << "MaximumCells: " << this->MaximumCells << " million\n";
  os << indent << "UseBox: " << this->UseBox << " Box: " << this->Box[0] << " " << this->Box[1] << " " << this->Box[2] << " "
     << this->Box[3] << " " << this->Box[4] << " " << this->Box[5] << "\n";
}
