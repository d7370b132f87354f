// Helpers for the VTK export tests: run the `vdbdag` command, a scratch
// folder, write small OpenVDB grids, and read VTK XML back with VTK's own
// readers (the same ones ParaView uses).
#pragma once
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include <openvdb/openvdb.h>
#include <vtkCompositeDataSet.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLMultiBlockDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace vtktest {

namespace fs = std::filesystem;

using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;

inline fs::path workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_vtk_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

inline fs::path sharedData(const std::string& relative) { return fs::path(VDBDAG_SHARED_DATA) / relative; }

inline void writeGrids(const fs::path& path, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.write(grids);
    file.close();
}

inline openvdb::GridPtrVecPtr readGrids(const fs::path& path) {
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.open(false);
    auto grids = file.getGrids();
    file.close();
    return grids;
}

inline vtkSmartPointer<vtkUnstructuredGrid> readVtu(const fs::path& path) {
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    return reader->GetOutput();
}

inline vtkSmartPointer<vtkImageData> readVti(const fs::path& path) {
    vtkNew<vtkXMLImageDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    return reader->GetOutput();
}

inline vtkSmartPointer<vtkMultiBlockDataSet> readVtm(const fs::path& path) {
    vtkNew<vtkXMLMultiBlockDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    return vtkMultiBlockDataSet::SafeDownCast(reader->GetOutputDataObject(0));
}

inline std::string blockName(vtkMultiBlockDataSet* blocks, unsigned i) {
    const char* name = blocks->HasMetaData(i) ? blocks->GetMetaData(i)->Get(vtkCompositeDataSet::NAME()) : nullptr;
    return name ? name : "";
}

// Index-space voxel box of a cell whose world-space corners came from
// `transform` (voxel (i,j,k) spans [i-0.5, i+0.5]): the min and max voxel.
inline openvdb::CoordBBox cellVoxels(vtkUnstructuredGrid* grid, vtkIdType cell, const openvdb::math::Transform& transform) {
    double b[6];
    grid->GetCellBounds(cell, b);
    const openvdb::Vec3d lo = transform.worldToIndex(openvdb::Vec3d(b[0], b[2], b[4]));
    const openvdb::Vec3d hi = transform.worldToIndex(openvdb::Vec3d(b[1], b[3], b[5]));
    const openvdb::Vec3d a = openvdb::math::minComponent(lo, hi), z = openvdb::math::maxComponent(lo, hi);
    return openvdb::CoordBBox(openvdb::Coord(int(std::lround(a.x() + 0.5)), int(std::lround(a.y() + 0.5)), int(std::lround(a.z() + 0.5))),
                              openvdb::Coord(int(std::lround(z.x() - 0.5)), int(std::lround(z.y() - 0.5)), int(std::lround(z.z() - 0.5))));
}

} // namespace vtktest
