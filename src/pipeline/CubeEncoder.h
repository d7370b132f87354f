// The out-of-core encoder (SSVDAG paper §4.2): one grid read cube by cube
// from a CubeSource. Per layer: the cubes' sub-DAGs are built several at a
// time (TBB) and merged in Morton order (dag/SubDagMerge.h); the values are
// then gathered cube by cube in the final DAG's attribute order. The result
// is the same EncodedGrid whatever the cube size, the budget and the thread
// count, so the file is byte-identical. It is the one encoder: a grid in
// memory (encodeGrid) is encoded through it too.
//
// Bounded: the cubes in flight (at most `workers`, each within its share of
// the budget), the value windows being coded (one per core, ValueWindows.h,
// or PredictedWindows.h for integers) and the reduced DAG; the coded values
// wait in a scratch file (CubeBudget::spillNear). Not yet bounded: the
// reduced DAG itself, and the attribute array of a layer whose coding needs
// it whole (a lossy tolerance, colour quantisation, or several processes).
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "src/pipeline/CubeTeam.h"
#include "src/pipeline/GridCodec.h"
#include "src/volume/CubeSource.h"

namespace vdbdag::pipeline {

struct CubeBudget {
    uint64_t bytes = 256ull << 20;  // working memory of the cubes in flight, all workers together
    unsigned workers = 0;           // cubes in flight; 0 = TBB's concurrency
    std::optional<unsigned> cubeLog2;  // force the cube size (tests); else the largest that fits
    // Where the coded values of a layer go while the rest is encoded (a
    // scratch file in this path's folder); empty: kept in memory.
    std::string spillNear;
    // Bytes of each such scratch space kept in memory before the file
    // (ScratchFile.h): none under a tight limit.
    uint64_t spillInMemory = 0;
};

// Rough working bytes per brick of a cube being reduced or gathered.
uint64_t cubeBytesPerBrick(unsigned valueSize);
// Value windows coded at once within the budget (at least 1, at most the
// workers), by what the windows are (ValueWindows.h, PredictedWindows.h).
enum class WindowKind { Palette, PredictedIntegers, PredictedFloats };
unsigned valueWindowsInFlight(const CubeBudget& budget, unsigned valueSize, WindowKind kind);

// --normals: the normals come from source.normals() (a grid in memory has
// them; a .vdb read region by region computes them cube by cube), gathered
// in attribute order and quantised as they arrive (attributes::
// NormalQuantizer); a source that cannot give them (a dense scan's) is
// refused with a vdbdag::Error.
// With a team of several processes (CubeTeam.h), every process must call
// this with the same input and options; only process 0's result holds the
// coded values (the others' are headers and DAGs).
format::EncodedGrid encodeGridByCubes(CubeSource& source, const EncodeOptions& options, const CubeBudget& budget, CubeTeam& team = soloTeam());

// Whole files: the grids in order, each released (source and attribute
// arrays) as soon as it is coded; `onGrid(index, count)` before each grid.
format::SsvdagScene encodeSourcesByCubes(std::vector<std::unique_ptr<CubeSource>> grids, std::vector<uint8_t> fileMetadata,
                                         const EncodeOptions& options, const CubeBudget& budget, const GridProgress& onGrid = {},
                                         CubeTeam& team = soloTeam());

} // namespace vdbdag::pipeline
