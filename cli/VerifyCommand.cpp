// `vdbdag verify IN.vdb [--json] [--memory-limit SIZE] [--scratch DIR]`:
// parses the request, runs app::verifyFile (app/VerifyFile.h) on the input
// or on each frame of a pattern, and prints what differs. Exit 0 only if
// identical.
#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/VerifyFile.h"
#include "cli/ByteSize.h"
#include "cli/Commands.h"
#include "cli/DenseInputOptions.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/format/FrameSequence.h"
#include "src/util/Error.h"
#include "src/util/FramePattern.h"
#include "src/util/Progress.h"
#include "vdb_bridge/InputScene.h"

namespace vdbdag::cli {
namespace {

struct VerifyOptions {
    std::string input, scratch, encoded;
    std::optional<uint32_t> frame;  // --encoded is a sequence: the frame compared with the input (an index)
    bool json = false, noSymmetry = false, topologyOnly = false;
    uint64_t memoryLimit = 0;
    ReadLimitOptions limits;  // what the .ssvdag file may expand to (a file from elsewhere, --encoded)
    DenseInputOptions dense;  // a scan: read as `encode` reads it
};

// Verifies one input and prints (or, with `batch`, adds) its report;
// true when identical.
bool verifyAndReport(const VerifyOptions& opt, std::optional<int64_t> frame, nlohmann::json* batch) {
    app::VerifyRequest request;
    request.input = opt.input, request.encoded = opt.encoded, request.frame = opt.frame, request.scratch = opt.scratch;
    request.noSymmetry = opt.noSymmetry, request.topologyOnly = opt.topologyOnly, request.memoryLimit = opt.memoryLimit;
    request.limits = opt.limits.limits(0);  // compared cube by cube: no copy of the whole
    const app::DenseInputs dense = opt.dense.inputs();
    dense.checkApplies(opt.input);
    if (bridge::inputKindOf(opt.input) == bridge::InputKind::Dense) {
        request.dense = dense.resolve(opt.input);
        request.dense.showProgress = false;         // verify's own progress line
        request.dense.limits = opt.limits.limits(1);  // --max-memory, --max-voxels: the import holds the samples once (as `import`)
    }
    app::VerifyResult verified = app::verifyFile(request);
    const bridge::CompareResult& result = verified.result;
    nlohmann::json& report = verified.report;
    if (frame) report["frame"] = *frame;
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
    CLI::App* cmd = app.add_subcommand("verify", "Check that a .vdb file or a scan survives the round trip through .ssvdag bit for bit (or that an .ssvdag file holds it), region by region");
    cmd->add_option("input", opt->input,
                    "input .vdb file (or a NanoVDB .nvdb, as its grids read through NanoVDB; or a scan: NIfTI, NRRD, MetaImage, raw or DICOM, "
                    "as `encode` reads it with the same options), or a frame pattern (smoke.####.vdb): each frame, "
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
    opt->dense.addTo(*cmd);
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
