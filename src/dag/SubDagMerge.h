// Building a DAG from the sub-DAGs of its cubes (SSVDAG paper §4.2): a grid
// too big to reduce at once is cut into aligned cubes of 2^cubeLog2 voxels;
// each cube's sub-DAG is built on its own (buildDag with the cube's corner
// as origin and cubeLog2 as size, several at once or on other machines), and
// the sub-DAGs are merged here in Morton order of their cubes, then raised
// to the root. The merge re-canonicalises every node against the global
// numbering, so it finds every match the in-core build finds and numbers
// the nodes the same way (LevelBuilder.h): the result equals buildDag of
// the whole grid, whatever the cube size.
#pragma once
#include <vector>

#include "src/dag/DagBuilder.h"
#include "src/dag/LevelBuilder.h"

namespace vdbdag::dag {

class SubDagMerger {
public:
    // `whole`: the placement of the whole grid (placeRoot); cubeLog2 in
    // [3, whole.log2Size).
    SubDagMerger(const RootPlacement& whole, unsigned cubeLog2, bool symmetry);

    // The sub-DAG of cube `cube` (in cube units from the whole origin), which
    // must come after every cube added before in Morton order. A cube that is
    // exactly one active tile is the sub-DAG of that tile alone.
    void add(CellCoord cube, const ReducedDag& sub);

    // Raises the cubes to the root, with the active tiles larger than a cube
    // (any order; `tileCells[i]` in units of 2^tileLog2[i]), and counts
    // references. The merger is spent afterwards.
    ReducedDag finish(const std::vector<std::pair<CellCoord, unsigned>>& largeTiles);

    unsigned cubeLog2() const { return cubeLog2_; }
    const ReducedDag& partial() const { return dag_; }

private:
    ReducedDag dag_;
    unsigned cubeLog2_;
    LevelBuilder levels_;
    std::vector<Instance> cubes_;
};

// The cubes of 2^cubeLog2 voxels of `topology` under `placement`, in Morton
// order, each with its bricks and its tiles up to the cube's size; tiles
// larger than a cube go to `largeTiles`.
struct TopologyCube {
    CellCoord cell;
    GridTopology topology;
};
std::vector<TopologyCube> splitIntoCubes(const GridTopology& topology, const RootPlacement& placement, unsigned cubeLog2,
                                         std::vector<std::pair<CellCoord, unsigned>>& largeTiles);

// buildDag by cubes of 2^cubeLog2 (for tests and for in-memory grids): the
// same result as buildDag(topology, options).
ReducedDag buildDagByCubes(const GridTopology& topology, const BuildOptions& options, unsigned cubeLog2);

} // namespace vdbdag::dag
