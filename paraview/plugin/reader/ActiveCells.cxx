#include "ActiveCells.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"

#include <cstring>
#include <stdexcept>
#include <vector>

vtkSmartPointer<vtkDataArray> ValueArray(const VolumeGrid& grid, const std::string& name, vtkIdType tuples)
{
  vtkSmartPointer<vtkDataArray> array;
  const std::string& type = grid.type;
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
  array->SetName(name.c_str());
  array->SetNumberOfTuples(tuples);
  return array;
}

vtkSmartPointer<vtkUnstructuredGrid> BuildActiveCells(const VolumeSource& source, size_t g, const vdbdag::IndexBBox& box,
  const std::string& name, uint64_t maxCells, const std::string& path)
{
  const VolumeGrid& grid = source.grids().at(g);
  const std::array<double, 16>& m = grid.indexToWorld;
  const unsigned row = grid.valueSize;
  std::vector<float> points;       // 8 corners per cell
  std::vector<uint8_t> values;     // row bytes per cell (none for a mask grid)
  uint64_t cells = 0;
  bool over = false;
  source.forEachActive(g, box, [&](const std::array<int64_t, 3>& c, unsigned log2, const void* value) {
    if (cells == maxCells)
    {
      over = true;
      return false;
    }
    ++cells;
    const double n = double(int64_t(1) << log2);
    // VTK's hexahedron order: the bottom face counter-clockwise, then the top.
    static const int corner[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
    for (const auto& k : corner)
    {
      const double ijk[3] = { double(c[0]) - 0.5 + k[0] * n, double(c[1]) - 0.5 + k[1] * n, double(c[2]) - 0.5 + k[2] * n };
      for (int r = 0; r < 3; ++r)
        points.push_back(float(ijk[0] * m[r] + ijk[1] * m[4 + r] + ijk[2] * m[8 + r] + m[12 + r]));
    }
    if (row)
      values.insert(values.end(), static_cast<const uint8_t*>(value), static_cast<const uint8_t*>(value) + row);
    return true;
  });
  if (over)
    throw std::runtime_error(path + ": grid '" + name + "' has more than " + std::to_string(maxCells) +
      " active cells in the box (Maximum Cells; choose a Box, or use the image output)");

  auto out = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkFloatArray> coords;
  coords->SetNumberOfComponents(3);
  coords->SetNumberOfTuples(vtkIdType(cells * 8));
  if (!points.empty())
    std::memcpy(coords->GetPointer(0), points.data(), points.size() * sizeof(float));
  vtkNew<vtkPoints> pts;
  pts->SetData(coords);
  out->SetPoints(pts);
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  offsets->SetNumberOfTuples(vtkIdType(cells + 1));
  connectivity->SetNumberOfTuples(vtkIdType(cells * 8));
  for (vtkIdType i = 0; i <= vtkIdType(cells); ++i)
    offsets->SetValue(i, 8 * i);
  for (vtkIdType i = 0; i < vtkIdType(cells * 8); ++i)
    connectivity->SetValue(i, i);
  vtkNew<vtkCellArray> hexahedra;
  hexahedra->SetData(offsets, connectivity);
  out->SetCells(VTK_HEXAHEDRON, hexahedra);

  vtkSmartPointer<vtkDataArray> array = ValueArray(grid, name, vtkIdType(cells));
  if (row && cells)
    std::memcpy(array->GetVoidPointer(0), values.data(), values.size());
  else if (cells) // a mask grid: every cell is active
    std::memset(array->GetVoidPointer(0), 1, size_t(cells));
  out->GetCellData()->AddArray(array);
  if (array->GetNumberOfComponents() == 1)
    out->GetCellData()->SetActiveScalars(array->GetName());
  return out;
}
