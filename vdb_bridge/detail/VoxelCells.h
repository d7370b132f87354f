// Private: builds a vtkUnstructuredGrid of voxel-shaped cells in world space.
// A voxel at index (i,j,k) is the index-space cube [i-0.5, i+0.5]^3 (OpenVDB
// puts voxel centres on integer coordinates), mapped through the grid's
// transform; a tile or a DAG node is one cell spanning its whole box (never
// expanded). Cells are VTK_VOXEL when the transform is an axis-aligned
// positive scale plus translation (VTK_VOXEL must be axis-aligned), else
// VTK_HEXAHEDRON with the same corners. Corners are shared between the
// voxels of one OpenVDB leaf (a 9^3 table), which keeps the point count near
// the cell count for narrow bands; boxes get their own 8 corners.
// Connectivity is stored with 32-bit indices while they fit.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <openvdb/openvdb.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

namespace vdbdag::bridge::detail {

class VoxelCellBuilder {
public:
    explicit VoxelCellBuilder(const openvdb::math::Transform& transform);
    // Row-major affine map, world = [i j k 1] * M (GridRecord::indexToWorld).
    explicit VoxelCellBuilder(const std::array<double, 16>& indexToWorld);

    void beginLeaf(const openvdb::Coord& leafOrigin);  // corner sharing within an 8^3 leaf
    void addVoxel(const openvdb::Coord& ijk);          // inside the current leaf
    void addBox(const openvdb::CoordBBox& box);        // inclusive voxel box, one cell
    uint64_t cellCount() const { return cells_; }
    bool axisAligned() const { return axisAligned_; }

    vtkSmartPointer<vtkUnstructuredGrid> finish();

private:
    int64_t addPoint(double i, double j, double k);
    void addCell(const std::array<int64_t, 8>& cornersXyzOrder);

    std::function<openvdb::Vec3d(const openvdb::Vec3d&)> toWorld_;
    bool axisAligned_ = false;
    std::vector<float> points_;
    std::vector<int64_t> connectivity_;
    uint64_t cells_ = 0;
    openvdb::Coord leafOrigin_;
    std::array<int64_t, 9 * 9 * 9> leafCorners_{};
};

// True when a vec3 grid holds colours (its name says color/colour/rgb or is
// Houdini's "Cd"): exported as 3-component unsigned char.
bool isColourGrid(const openvdb::GridBase& grid);

} // namespace vdbdag::bridge::detail
