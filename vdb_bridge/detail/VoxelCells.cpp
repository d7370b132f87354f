// See VoxelCells.h.
#include "vdb_bridge/detail/VoxelCells.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkFloatArray.h>
#include <vtkPoints.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>

namespace vdbdag::bridge::detail {
namespace {

bool isAxisAlignedPositive(const openvdb::Mat4d& m) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (r != c && m(r, c) != 0.0) return false;
    return m(0, 0) > 0 && m(1, 1) > 0 && m(2, 2) > 0 && m(0, 3) == 0 && m(1, 3) == 0 && m(2, 3) == 0 && m(3, 3) == 1;
}

} // namespace

VoxelCellBuilder::VoxelCellBuilder(const openvdb::math::Transform& transform) {
    const auto map = transform.baseMap();
    if (map && map->isLinear()) {
        const openvdb::Mat4d m = map->getAffineMap()->getMat4();
        axisAligned_ = isAxisAlignedPositive(m);
        toWorld_ = [m](const openvdb::Vec3d& p) { return m.transform(p); };
    } else {
        toWorld_ = [transform](const openvdb::Vec3d& p) { return transform.indexToWorld(p); };
    }
}

VoxelCellBuilder::VoxelCellBuilder(const std::array<double, 16>& a) {
    openvdb::Mat4d m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = a[size_t(4 * r + c)];
    axisAligned_ = isAxisAlignedPositive(m);
    toWorld_ = [m](const openvdb::Vec3d& p) { return m.transform(p); };
}

int64_t VoxelCellBuilder::addPoint(double i, double j, double k) {
    const openvdb::Vec3d w = toWorld_(openvdb::Vec3d(i, j, k));
    points_.push_back(float(w.x()));
    points_.push_back(float(w.y()));
    points_.push_back(float(w.z()));
    return int64_t(points_.size() / 3 - 1);
}

void VoxelCellBuilder::addCell(const std::array<int64_t, 8>& c) {
    // c is in x-fastest corner order (VTK_VOXEL's); a hexahedron goes around each face.
    if (axisAligned_)
        connectivity_.insert(connectivity_.end(), c.begin(), c.end());
    else
        connectivity_.insert(connectivity_.end(), {c[0], c[1], c[3], c[2], c[4], c[5], c[7], c[6]});
    ++cells_;
}

void VoxelCellBuilder::beginLeaf(const openvdb::Coord& leafOrigin) {
    leafOrigin_ = leafOrigin;
    leafCorners_.fill(-1);
}

void VoxelCellBuilder::addVoxel(const openvdb::Coord& ijk) {
    const openvdb::Coord local = ijk - leafOrigin_;
    std::array<int64_t, 8> corners{};
    for (int n = 0; n < 8; ++n) {
        const int dx = n & 1, dy = (n >> 1) & 1, dz = (n >> 2) & 1;
        int64_t& slot = leafCorners_[size_t((local.x() + dx) + 9 * ((local.y() + dy) + 9 * (local.z() + dz)))];
        if (slot < 0) slot = addPoint(ijk.x() + dx - 0.5, ijk.y() + dy - 0.5, ijk.z() + dz - 0.5);
        corners[size_t(n)] = slot;
    }
    addCell(corners);
}

void VoxelCellBuilder::addBox(const openvdb::CoordBBox& box) {
    std::array<int64_t, 8> corners{};
    for (int n = 0; n < 8; ++n) {
        const double x = (n & 1) ? box.max().x() + 0.5 : box.min().x() - 0.5;
        const double y = ((n >> 1) & 1) ? box.max().y() + 0.5 : box.min().y() - 0.5;
        const double z = ((n >> 2) & 1) ? box.max().z() + 0.5 : box.min().z() - 0.5;
        corners[size_t(n)] = addPoint(x, y, z);
    }
    addCell(corners);
}

vtkSmartPointer<vtkUnstructuredGrid> VoxelCellBuilder::finish() {
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    vtkNew<vtkFloatArray> coords;
    coords->SetNumberOfComponents(3);
    coords->SetNumberOfTuples(vtkIdType(points_.size() / 3));
    std::copy(points_.begin(), points_.end(), coords->GetPointer(0));
    std::vector<float>().swap(points_);
    vtkNew<vtkPoints> points;
    points->SetData(coords);
    grid->SetPoints(points);

    vtkNew<vtkCellArray> cells;
    const bool small = connectivity_.size() < uint64_t(std::numeric_limits<int32_t>::max());
    auto fill = [&](auto offsets, auto conn) {
        offsets->SetNumberOfValues(vtkIdType(cells_ + 1));
        for (uint64_t c = 0; c <= cells_; ++c) offsets->SetValue(vtkIdType(c), decltype(offsets->GetValue(0))(8 * c));
        conn->SetNumberOfValues(vtkIdType(connectivity_.size()));
        for (size_t n = 0; n < connectivity_.size(); ++n) conn->SetValue(vtkIdType(n), decltype(conn->GetValue(0))(connectivity_[n]));
        cells->SetData(offsets, conn);
    };
    if (small)
        fill(vtkSmartPointer<vtkTypeInt32Array>::New(), vtkSmartPointer<vtkTypeInt32Array>::New());
    else
        fill(vtkSmartPointer<vtkTypeInt64Array>::New(), vtkSmartPointer<vtkTypeInt64Array>::New());
    std::vector<int64_t>().swap(connectivity_);
    grid->SetCells(axisAligned_ ? VTK_VOXEL : VTK_HEXAHEDRON, cells);
    return grid;
}

bool isColourGrid(const openvdb::GridBase& grid) {
    if (grid.valueType().find("vec3") != 0) return false;
    std::string name = grid.getName();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return name == "cd" || name.find("color") != std::string::npos || name.find("colour") != std::string::npos ||
           name.find("rgb") != std::string::npos;
}

} // namespace vdbdag::bridge::detail
