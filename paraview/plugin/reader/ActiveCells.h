// The reader's second output: a grid's active voxels and tiles as cells of a
// vtkUnstructuredGrid (a hexahedron per voxel and per tile, from corner -
// 0.5 to corner + size - 0.5 in index space, through the grid's transform),
// with the values as cell data named as the grid: what `vdbdag export`
// writes as .vtu, read in place.
#ifndef ActiveCells_h
#define ActiveCells_h

#include "VolumeSource.h"

#include "vtkDataArray.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <string>

// A VTK array for `tuples` values of the grid's type, named `name`: float,
// double, int32 and int64 as themselves, vectors as 3 components, bool and
// mask as unsigned char (0/1). The reader's image and its cells both use it.
vtkSmartPointer<vtkDataArray> ValueArray(const VolumeGrid& grid, const std::string& name, vtkIdType tuples);

// Throws std::runtime_error when the box holds more than maxCells cells.
vtkSmartPointer<vtkUnstructuredGrid> BuildActiveCells(const VolumeSource& source, size_t grid, const vdbdag::IndexBBox& box,
  const std::string& name, uint64_t maxCells, const std::string& path);

#endif
