// The reader's second output: a grid's active voxels and tiles as cells of a
// vtkUnstructuredGrid (a hexahedron per voxel and per tile, from corner -
// 0.5 to corner + size - 0.5 in index space, through the grid's transform),
// with the values as cell data named as the grid: what `vdbdag export`
// writes as .vtu, read in place.
#ifndef ActiveCells_h
#define ActiveCells_h

#include "VolumeSource.h"

#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <string>

// Throws std::runtime_error when the box holds more than maxCells cells.
vtkSmartPointer<vtkUnstructuredGrid> BuildActiveCells(const VolumeSource& source, size_t grid, const vdbdag::IndexBBox& box,
  const std::string& name, uint64_t maxCells, const std::string& path);

#endif
