// See VerifyFile.h.
#include "app/VerifyFile.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "app/EncodeFile.h"
#include "app/MemoryBudget.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/ParallelFor.h"
#include "src/util/Progress.h"
#include "src/util/TemporaryFiles.h"
#include "vdb_bridge/InputScene.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbImport.h"
#include "vdb_bridge/VdbStreamCompare.h"

namespace vdbdag::app {
namespace {

struct Verified {
    bridge::CompareResult result;
    uint64_t bytes = 0;  // the .ssvdag file's size
    size_t grids = 0;
};

// Removes a file when it goes out of scope (and, through the guard, on an interrupt).
struct RemovedAfterwards {
    explicit RemovedAfterwards(std::string p) : path(std::move(p)), guard(path) {}
    ~RemovedAfterwards() {
        std::error_code ignored;
        std::filesystem::remove(path, ignored);
    }
    std::string path;
    TemporaryGuard guard;
};

// An .ssvdag file against the input, cube by cube.
void compareByCubes(const VerifyRequest& opt, const std::string& encoded, Progress& progress, uint64_t from, uint64_t units, Verified& out) {
    format::ReadOptions readOptions;
    readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
    readOptions.keepValueWindows = true;
    readOptions.limits = opt.limits;  // compared cube by cube: no copy of the whole
    if (encoded == opt.encoded) readOptions.frame = opt.frame;
    const format::SsvdagScene scene = format::readSceneFile(encoded, readOptions);
    out.grids = scene.grids.size();
    std::string step;
    out.result = bridge::compareSceneWithFile(opt.input, scene, !opt.topologyOnly, [&](const std::string& s, uint64_t done, uint64_t total) {
        if (s != step) progress.setLabel("verify: " + (step = s));
        if (total) progress.set(from + std::min(done, total) * (units - 1) / total);
    });
}

// The file `encode` wrote (--encoded).
Verified verifyEncoded(const VerifyRequest& opt) {
    if (!bridge::canReadVdbByCubes(opt.input)) throw Error(opt.input + ": --encoded needs a .vdb file with grid offsets (not an OpenVDB stream)");
    Progress progress("verify", 1000);
    Verified out;
    compareByCubes(opt, opt.encoded, progress, 0, 1000, out);
    out.bytes = std::filesystem::file_size(opt.encoded);
    progress.finish();
    return out;
}

// Region by region, through a temporary .ssvdag file.
Verified verifyByCubes(const VerifyRequest& opt) {
    const std::filesystem::path folder = opt.scratch.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(opt.scratch);
    const RemovedAfterwards encoded(temporaryNameFor((folder / std::filesystem::path(opt.input).filename()).string(), ".ssvdag"));
    constexpr uint64_t kUnits = 1000;  // encode, then compare
    Progress progress("verify: encode", 2 * kUnits);
    Verified out;
    {
        bridge::ImportOptions importOptions;
        importOptions.topologyOnly = opt.topologyOnly;
        bridge::VdbCubeInput input = bridge::openVdbCubes(opt.input, importOptions, encoded.path, app::scratchInMemory(opt.memoryLimit ? opt.memoryLimit : app::defaultMemoryLimit()));
        pipeline::EncodeOptions options;
        options.symmetry = !opt.noSymmetry;
        options.computeSvdagStats = false;  // as `encode` does by default: the same file, byte for byte
        const size_t steps = std::max<size_t>(1, input.grids.size() * pipeline::kEncodeSteps);
        size_t stepsStarted = 0;
        options.onStep = [&](const char*) { progress.set(stepsStarted++ * kUnits / steps); };
        options.onStepProgress = [&](uint64_t done, uint64_t total) {
            if (stepsStarted && total) progress.set(((stepsStarted - 1) * kUnits + std::min(done, total) * kUnits / total) / steps);
        };
        format::SsvdagScene scene = pipeline::encodeSourcesByCubes(std::move(input.grids), input.fileMetadata, options, app::cubeBudget(opt.memoryLimit, encoded.path));
        std::ofstream file(encoded.path, std::ios::binary | std::ios::trunc);
        if (!file) throw Error(encoded.path + ": cannot be created (the verify's temporary file; choose another folder with --scratch)");
        out.bytes = format::writeSceneReleasing(scene, file);
        file.close();
        if (!file) throw Error(encoded.path + ": could not be written (the verify's temporary file; is the disk full?)");
    }
    compareByCubes(opt, encoded.path, progress, kUnits, kUnits, out);
    progress.finish();
    return out;
}

// Whole, in memory (an OpenVDB stream has no offsets to read regions by).
Verified verifyWhole(const VerifyRequest& opt) {
    bridge::ImportOptions importOptions;
    importOptions.topologyOnly = opt.topologyOnly;
    const bridge::ImportResult imported = bridge::importVdb(opt.input, importOptions);
    pipeline::EncodeOptions options;
    options.symmetry = !opt.noSymmetry;
    options.keepAttributes = false;  // written and read back
    const std::vector<uint8_t> bytes = format::writeScene(pipeline::encodeVolume(imported.volume, options));
    const Volume decoded = pipeline::decodeScene(format::readScene(bytes, opt.input + " (in memory)"));
    return {bridge::compareWithFile(opt.input, decoded, !opt.topologyOnly), bytes.size(), decoded.grids.size()};
}

// A NanoVDB file: its grids as NanoVDB's converter reads them (as `encode`
// reads it) go to a temporary .vdb in the scratch folder, which is verified
// as any .vdb is.
Verified verifyNanoVdb(const VerifyRequest& opt) {
    if (!opt.encoded.empty()) throw Error(opt.input + ": --encoded compares with a .vdb file; verify a .nvdb alone");
    const std::filesystem::path folder = opt.scratch.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(opt.scratch);
    const RemovedAfterwards vdb(temporaryNameFor((folder / std::filesystem::path(opt.input).filename()).string(), ".vdb"));
    bridge::exportVdb(bridge::importNanoVdb(opt.input).volume, vdb.path);
    VerifyRequest asVdb = opt;
    asVdb.input = vdb.path;
    return bridge::canReadVdbByCubes(asVdb.input) ? verifyByCubes(asVdb) : verifyWhole(asVdb);
}

// A scan: its grids as `encode` imports them go to a temporary .vdb in the
// scratch folder (the import whole, in memory: 4 bytes a sample, and the
// .vdb's copy while it is written). The .ssvdag compared with it, cube by
// cube: --encoded, or what `encode` writes for the scan with the same
// options (app::encodeFile, into the scratch folder: the same bytes).
Verified verifyScan(const VerifyRequest& opt) {
    const std::filesystem::path folder = opt.scratch.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(opt.scratch);
    const std::string stem = (folder / std::filesystem::path(opt.input).filename()).string();
    const RemovedAfterwards vdb(temporaryNameFor(stem, ".vdb"));
    {
        bridge::DenseImportOptions dense = opt.dense;
        dense.cubesNear.clear();
        bridge::exportVdb(bridge::importDense(opt.input, dense).volume, vdb.path);
    }
    VerifyRequest asVdb = opt;
    asVdb.input = vdb.path;
    if (!opt.encoded.empty()) return verifyEncoded(asVdb);
    const RemovedAfterwards encoded(temporaryNameFor(stem, ".ssvdag"));
    EncodeRequest request;
    request.input = opt.input, request.output = encoded.path, request.force = true, request.dense = opt.dense;
    request.noSymmetry = opt.noSymmetry, request.topologyOnly = opt.topologyOnly, request.memoryLimit = opt.memoryLimit, request.scratch = folder.string();
    encodeFile(request);
    asVdb.encoded = encoded.path;
    return verifyEncoded(asVdb);
}

} // namespace

VerifyResult verifyFile(const VerifyRequest& opt) {
    const bridge::InputKind kind = bridge::inputKindOf(opt.input);
    const Verified verified = kind == bridge::InputKind::Dense     ? verifyScan(opt)
                              : kind == bridge::InputKind::NanoVdb ? verifyNanoVdb(opt)
                              : !opt.encoded.empty()                   ? verifyEncoded(opt)
                              : bridge::canReadVdbByCubes(opt.input) ? verifyByCubes(opt)
                                                                     : verifyWhole(opt);
    const bridge::CompareResult& result = verified.result;
    nlohmann::json report{{"input", opt.input}, {"identical", result.identical}, {"ssvdag_bytes", verified.bytes},
                          {"header_differences", result.headerDifferences}, {"grids", nlohmann::json::array()}};
    for (const auto& d : result.topology)
        report["grids"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"only_in_original", d.onlyInA},
                                   {"only_in_decoded", d.onlyInB}, {"examples", d.examples}});
    report["values"] = nlohmann::json::array();
    for (const auto& d : result.values)
        report["values"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"active_values_differing", d.activeValues},
                                    {"inactive_values_differing", d.inactiveValues}, {"examples", d.examples}});
    return {result, verified.bytes, verified.grids, std::move(report)};
}

} // namespace vdbdag::app
