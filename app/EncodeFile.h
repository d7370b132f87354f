// `vdbdag encode` of one input as a library call: a .vdb, a NanoVDB .nvdb,
// a dense scan (.raw, NRRD, MetaImage, NIfTI) or a DICOM series to one
// .ssvdag file, written atomically, with the report `encode --json` prints.
// The command line (cli/EncodeCommand.cpp) parses its options into an
// EncodeRequest and prints the result; other programs call it directly.
//
// How the input is read: a scan cube by cube from a scratch file (with a
// memory limit, under mpirun, or when it would not fit in memory), a .vdb
// region by region where its grids allow it, a stream, --normals or a
// NanoVDB file whole; the output is the same bytes either way.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/SeriesReference.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::app {

struct EncodeRequest {
    std::string input, output;  // one input (a file, or a DICOM folder) to one .ssvdag
    // The files the input reads (the input, a header's data file, a DICOM
    // series' slices): the output may be none of them. Empty: {input}.
    std::vector<std::string> inputFiles;
    bool force = false;  // replace an existing output (never an input, a link or a device)
    // What is read: grids by name (none: all), unsupported grids skipped
    // rather than refused, the active topology alone (mask grids).
    std::vector<std::string> grids;
    bool skipUnsupported = false, topologyOnly = false;
    // A dense scan's layout, series and threshold, resolved
    // (cli/DenseInputOptions.h); unused for .vdb and .nvdb inputs.
    bridge::DenseImportOptions dense;
    // How it is coded (the options of `vdbdag encode --help`).
    bool noSymmetry = false, noCompress = false, noPredict = false, svdagStats = false;
    int placementTrials = 1;
    // A 4-D scan's volumes: a key volume every keyEvery, each other coded
    // with the volume before as its reference where that is smaller
    // (pipeline/SeriesReference.h; 1: every volume alone).
    unsigned keyEvery = pipeline::kDefaultKeyEvery;
    double absError = 0, relError = 0;
    unsigned colourBits = 0, normalBits = 0;
    std::vector<std::string> colourGrids;
    std::string normalGrid;
    // Resources: the working memory (0: half the physical memory), the
    // scratch folder (empty: the output's), worker threads (0: one per core).
    uint64_t memoryLimit = 0;
    std::string scratch;
    unsigned threads = 0;
};

struct EncodeHooks {
    // The processes sharing the cubes (mpirun); null: this process alone.
    pipeline::CubeTeam* team = nullptr;
    // Each warning about the input (a grid skipped, ...), and each note
    // about the result; unset: dropped.
    std::function<void(const std::string&)> warning, note;
    // Progress as a fraction 0..1, beside the terminal's own line (a
    // sequence's encode shows its frames' progress as one).
    std::function<void(double)> onProgress;
};

struct EncodeResult {
    // False on a process of an mpirun team other than the first, which
    // writes the file and reports.
    bool written = false;
    nlohmann::json report;              // as `encode --json` prints it
    bridge::ThresholdReport threshold;  // a dense scan's threshold, for the text report
};

// Throws vdbdag::Error naming the input on a refusal; nothing is written
// then (the output appears whole or not at all).
EncodeResult encodeFile(const EncodeRequest& request, const EncodeHooks& hooks = {});

} // namespace vdbdag::app
