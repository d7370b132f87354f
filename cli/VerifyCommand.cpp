// `vdbdag verify IN.vdb [--json] [--memory-limit SIZE] [--scratch DIR]`:
// encode, write the .ssvdag, read it back, decode, and compare with the
// original file using OpenVDB alone: headers, topology, every active value
// and every stored inactive value, bit for bit. Exit 0 only if identical.
//
// A .vdb with grid offsets goes the way `encode` takes it (region by
// region, within --memory-limit) into a temporary file in the scratch
// folder, and is compared cube by cube (vdb_bridge/VdbStreamCompare.h):
// neither side is ever a whole grid. An OpenVDB stream is read, encoded
// and compared whole, in memory (vdb_bridge/VdbCompare.h).
#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <fstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/ByteSize.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "app/MemoryBudget.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/FramePattern.h"
#include "src/format/FrameSequence.h"
#include "src/util/Progress.h"
#include "src/util/TemporaryFiles.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/InputScene.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbCompare.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbImport.h"
#include "vdb_bridge/VdbStreamCompare.h"

namespace vdbdag::cli {
namespace {

struct VerifyOptions {
    std::string input, scratch, encoded;
    std::optional<uint32_t> frame;  // --encoded is a sequence: the frame compared with the input (an index)
    bool json = false, noSymmetry = false, topologyOnly = false;
    uint64_t memoryLimit = 0;
    ReadLimitOptions limits;  // what the .ssvdag file may expand to (a file from elsewhere, --encoded)
};

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
void compareByCubes(const VerifyOptions& opt, const std::string& encoded, Progress& progress, uint64_t from, uint64_t units, Verified& out) {
    format::ReadOptions readOptions;
    readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
    readOptions.keepValueWindows = true;
    readOptions.limits = opt.limits.limits(0);  // compared cube by cube: no copy of the whole
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
Verified verifyEncoded(const VerifyOptions& opt) {
    if (!bridge::canReadVdbByCubes(opt.input)) throw Error(opt.input + ": --encoded needs a .vdb file with grid offsets (not an OpenVDB stream)");
    Progress progress("verify", 1000);
    Verified out;
    compareByCubes(opt, opt.encoded, progress, 0, 1000, out);
    out.bytes = std::filesystem::file_size(opt.encoded);
    progress.finish();
    return out;
}

// Region by region, through a temporary .ssvdag file.
Verified verifyByCubes(const VerifyOptions& opt) {
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
Verified verifyWhole(const VerifyOptions& opt) {
    bridge::ImportOptions importOptions;
    importOptions.topologyOnly = opt.topologyOnly;
    const bridge::ImportResult imported = bridge::importVdb(opt.input, importOptions);
    pipeline::EncodeOptions options;
    options.symmetry = !opt.noSymmetry;
    const std::vector<uint8_t> bytes = format::writeScene(pipeline::encodeVolume(imported.volume, options));
    const Volume decoded = pipeline::decodeScene(format::readScene(bytes, opt.input + " (in memory)"));
    return {bridge::compareWithFile(opt.input, decoded, !opt.topologyOnly), bytes.size(), decoded.grids.size()};
}

// A NanoVDB file: its grids as NanoVDB's converter reads them (as `encode`
// reads it) go to a temporary .vdb in the scratch folder, which is verified
// as any .vdb is.
Verified verifyNanoVdb(const VerifyOptions& opt) {
    if (!opt.encoded.empty()) throw Error(opt.input + ": --encoded compares with a .vdb file; verify a .nvdb alone");
    const std::filesystem::path folder = opt.scratch.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(opt.scratch);
    const RemovedAfterwards vdb(temporaryNameFor((folder / std::filesystem::path(opt.input).filename()).string(), ".vdb"));
    bridge::exportVdb(bridge::importNanoVdb(opt.input).volume, vdb.path);
    VerifyOptions asVdb = opt;
    asVdb.input = vdb.path;
    return bridge::canReadVdbByCubes(asVdb.input) ? verifyByCubes(asVdb) : verifyWhole(asVdb);
}

// Verifies one input and prints (or, with `batch`, adds) its report;
// true when identical.
bool verifyAndReport(const VerifyOptions& opt, std::optional<int64_t> frame, nlohmann::json* batch) {
    const Verified verified = bridge::inputKindOf(opt.input) == bridge::InputKind::NanoVdb ? verifyNanoVdb(opt)
                              : !opt.encoded.empty()                   ? verifyEncoded(opt)
                              : bridge::canReadVdbByCubes(opt.input) ? verifyByCubes(opt)
                                                                     : verifyWhole(opt);
    const bridge::CompareResult& result = verified.result;
    nlohmann::json report{{"input", opt.input}, {"identical", result.identical}, {"ssvdag_bytes", verified.bytes},
                          {"header_differences", result.headerDifferences}, {"grids", nlohmann::json::array()}};
    if (frame) report["frame"] = *frame;
    for (const auto& d : result.topology)
        report["grids"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"only_in_original", d.onlyInA},
                                   {"only_in_decoded", d.onlyInB}, {"examples", d.examples}});
    report["values"] = nlohmann::json::array();
    for (const auto& d : result.values)
        report["values"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"active_values_differing", d.activeValues},
                                    {"inactive_values_differing", d.inactiveValues}, {"examples", d.examples}});
    if (opt.json) {
        if (batch) batch->push_back(report);
        else printJson(report);
    } else if (result.identical) {
        fmt::print("{}: identical after the round trip ({} grid(s), {} bytes encoded)\n", opt.input, verified.grids, verified.bytes);
    } else {
        fmt::print("{}: DIFFERS after the round trip\n", opt.input);
        for (const auto& h : result.headerDifferences) fmt::print("  {}\n", h);
        for (const auto& d : result.topology) {
            fmt::print("  grid {} '{}': {} voxels only in the original, {} only in the decoded grid\n", d.gridIndex, d.gridName, d.onlyInA, d.onlyInB);
            for (const auto& e : d.examples) fmt::print("    {}\n", e);
        }
        for (const auto& d : result.values) {
            fmt::print("  grid {} '{}': {} active and {} inactive values differ\n", d.gridIndex, d.gridName, d.activeValues, d.inactiveValues);
            for (const auto& e : d.examples) fmt::print("    {}\n", e);
        }
    }
    return result.identical;
}

} // namespace

void addVerifyCommand(CLI::App& app, int& exitCode) {
    auto opt = std::make_shared<VerifyOptions>();
    CLI::App* cmd = app.add_subcommand("verify", "Check that a .vdb file survives the round trip through .ssvdag bit for bit (or that an .ssvdag file holds it), region by region");
    cmd->add_option("input", opt->input,
                    "input .vdb file (or a NanoVDB .nvdb, as its grids read through NanoVDB), or a frame pattern (smoke.####.vdb): each frame, "
                    "against its frame of the sequence file --encoded names")
        ->required();
    cmd->add_flag("--no-symmetry", opt->noSymmetry, "verify the plain SVDAG encoding");
    cmd->add_flag("--topology-only", opt->topologyOnly, "verify the geometry-only encoding (topology and headers)");
    cmd->add_option("--encoded", opt->encoded, "compare this .ssvdag file (e.g. what `encode` wrote) with the input, instead of encoding one; a sequence file: the frame of the input's number")
        ->check(CLI::ExistingFile);
    cmd->add_option("--memory-limit", opt->memoryLimit, "working memory of the encode, as for `encode` (default: half the physical memory)")
        ->transform(byteSize());
    cmd->add_option("--scratch", opt->scratch, "folder for the encoded file and the scratch files while verifying (default: the system's temporary folder)")
        ->check(CLI::ExistingDirectory);
    cmd->add_flag("--json", opt->json, "print JSON");
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        if (opt->json) setQuiet(true);
        // Frames: a pattern (smoke.####.vdb), each frame verified; with
        // --encoded a sequence file, each against its frame of that number.
        std::vector<FrameFile> frames;
        const bool pattern = isFramePattern(opt->input) && !std::filesystem::exists(opt->input);
        if (pattern) {
            frames = expandFramePattern(opt->input);
            if (frames.empty()) throw Error(opt->input + ": no file matches this frame pattern");
        } else {
            frames.push_back({frameNumberOf(opt->input).value_or(0), opt->input});
        }
        std::optional<format::FrameList> sequence;
        if (!opt->encoded.empty()) {
            sequence = format::readFrameList(opt->encoded);
            if (!sequence->sequence) {
                if (pattern) throw Error(opt->encoded + ": holds one volume, not the sequence " + opt->input);
                sequence.reset();
            }
        }
        nlohmann::json reports = nlohmann::json::array();
        bool identical = true;
        std::set<int64_t> compared;
        for (const FrameFile& f : frames) {
            VerifyOptions one = *opt;
            one.input = f.path;
            if (sequence) {
                const auto& list = sequence->frames;
                const auto it = std::find_if(list.begin(), list.end(), [&](const format::FrameEntry& e) { return e.number == f.number; });
                if (it == list.end()) {
                    if (!pattern) throw Error(opt->encoded + ": a sequence with no frame " + std::to_string(f.number) + " (the number of " + f.path + ")");
                    identical = false;
                    reports.push_back({{"input", f.path}, {"frame", f.number}, {"identical", false}, {"header_differences", {"frame missing in " + opt->encoded}}});
                    if (!opt->json) fmt::print("{}: DIFFERS: {} has no frame {}\n", f.path, opt->encoded, f.number);
                    continue;
                }
                one.frame = uint32_t(it - list.begin());
                compared.insert(f.number);
            }
            setActivity(one.input, "verifying");
            identical = verifyAndReport(one, pattern ? std::optional<int64_t>(f.number) : std::nullopt, pattern ? &reports : nullptr) && identical;
        }
        if (sequence && pattern)
            for (const format::FrameEntry& e : sequence->frames)
                if (!compared.contains(e.number)) {
                    identical = false;
                    reports.push_back({{"frame", e.number}, {"identical", false}, {"header_differences", {"frame only in " + opt->encoded}}});
                    if (!opt->json) fmt::print("{}: DIFFERS: frame {} has no file matching {}\n", opt->encoded, e.number, opt->input);
                }
        if (pattern && opt->json) printJson(reports);
        exitCode = identical ? 0 : 1;
    });
}

} // namespace vdbdag::cli
