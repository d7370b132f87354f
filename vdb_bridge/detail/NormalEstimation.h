// Exact (unquantised) shading normals for `encode --normals K`, computed
// with OpenVDB's accessors and handed to the core as plain vectors in the
// record's input order (GridRecord::Normals), one per active voxel and tile:
//  - from a float/double level set (or any scalar field): the gradient by
//    central differences in index space; where a neighbour along an axis is
//    inactive (the narrow band's edge) that axis falls back to a one-sided
//    difference towards the active side (counted); the gradient is mapped to
//    world space by the transform's inverse Jacobian transpose, normalised.
//    A tile is evaluated at its centre voxel. A zero gradient (flat region)
//    stays a zero vector: the ONV encoder stores +z and counts it.
//  - from a vec3 normal grid: its values, normalised (zero stays zero).
#pragma once
#include <openvdb/openvdb.h>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge::detail {

// `topology` is the grid's active topology as imported (bricks and tiles).
GridRecord::Normals gradientNormals(const openvdb::FloatGrid& grid, const GridTopology& topology);
GridRecord::Normals gradientNormals(const openvdb::DoubleGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3SGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3DGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3IGrid& grid, const GridTopology& topology);

} // namespace vdbdag::bridge::detail
