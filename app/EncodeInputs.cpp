// See EncodeInputs.h.
#include "app/EncodeInputs.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "app/EncodeOutputs.h"
#include "app/EncodeSequence.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"

namespace vdbdag::app {
namespace {

// One input to one output on `team`, through `hooks` (a sequence's frame:
// its progress only).
EncodeResult encodeOne(const EncodeInputsRequest& request, const EncodeInputsHooks& hooks, const std::string& input, const std::string& output,
                       const EncodeHooks& fileHooks) {
    if (hooks.onInput) hooks.onInput(input);
    request.dense.checkApplies(input);
    EncodeRequest r = request.coding;
    r.input = input, r.output = output;
    r.inputFiles = denseInputFiles(input, request.dense);
    r.dense = bridge::denseFormatOf(input) != bridge::DenseFormat::None ? request.dense.resolve(input) : bridge::DenseImportOptions{};
    return encodeFile(r, fileHooks);
}

EncodeInputsResult encodeFrames(const EncodeInputsRequest& request, const EncodeInputsHooks& hooks, std::vector<FrameFile> frames,
                                const std::string& output, const std::string& described) {
    SequenceRequest sequence{frames, output, described, request.coding.scratch, request.coding.force};
    const auto frame = [&](size_t, const std::string& input, const std::string& frameOutput, const std::function<void(double)>& onProgress) {
        EncodeHooks frameHooks;
        frameHooks.team = &pipeline::soloTeam();  // each frame on one process alone
        frameHooks.warning = hooks.file.warning;
        frameHooks.onProgress = onProgress;
        return encodeOne(request, hooks, input, frameOutput, frameHooks).report;
    };
    pipeline::CubeTeam& team = hooks.file.team ? *hooks.file.team : pipeline::soloTeam();
    SequenceResult result = encodeSequence(sequence, team, frame);
    EncodeInputsResult out;
    out.shape = EncodeShape::Sequence, out.written = result.written, out.output = output;
    out.report = std::move(result.report), out.frames = std::move(frames);
    return out;
}

// The checks the command line's options make, for callers that fill a
// request themselves (Python).
void checkCoding(const EncodeRequest& c) {
    const auto refuse = [](const std::string& what) { throw Error("encode: " + what); };
    if (c.placementTrials < 1 || c.placementTrials > 64) refuse("--placement-trials is 1 to 64, not " + std::to_string(c.placementTrials));
    if (!std::isfinite(c.absError) || c.absError < 0) refuse("--abs-error must be a finite number above 0");
    if (!std::isfinite(c.relError) || c.relError < 0 || (c.relError != 0 && (c.relError < 1e-12 || c.relError > 0.5)))
        refuse("--rel-error is 1e-12 to 0.5");
    if (c.absError != 0 && c.relError != 0) refuse("--abs-error and --rel-error exclude each other");
    if (c.colourBits > 16) refuse("--colour-bits is 1 to 16, not " + std::to_string(c.colourBits));
    if (!c.colourGrids.empty() && c.colourBits == 0) refuse("--colour-grid needs --colour-bits");
    if (c.normalBits != 0 && c.normalBits != 10 && c.normalBits != 12 && c.normalBits != 16 && c.normalBits != 24 && c.normalBits != 32)
        refuse("--normals is 10, 12, 16, 24 or 32, not " + std::to_string(c.normalBits));
    if (!c.normalGrid.empty() && c.normalBits == 0) refuse("--normal-grid needs --normals");
    if (c.threads > 1024) refuse("--threads is 1 to 1024, not " + std::to_string(c.threads));
    if (!c.scratch.empty() && !std::filesystem::is_directory(c.scratch)) refuse("--scratch " + c.scratch + ": not a folder");
}

} // namespace

EncodeInputsResult encodeInputs(const EncodeInputsRequest& request, const EncodeInputsHooks& hooks) {
    const std::vector<std::string>& inputs = request.inputs;
    if (inputs.empty()) throw Error("no input given");
    checkCoding(request.coding);
    // A folder of .vdb or .nvdb files (frames of a cache, no DICOM among
    // them): its files as a sequence, numbered by their names.
    if (inputs.size() == 1)
        if (const std::optional<std::vector<std::string>> files = cacheFrameFiles(inputs[0]))
            return encodeFrames(request, hooks, framesOfList(*files), request.output.empty() ? defaultOutputFor(inputs[0]) : request.output, inputs[0]);
    if (inputs.size() == 1 && isFramePattern(inputs[0]) && !std::filesystem::exists(inputs[0])) {
        std::vector<FrameFile> frames = expandFramePattern(inputs[0]);
        if (frames.empty()) throw Error(inputs[0] + ": no file matches this frame pattern");
        return encodeFrames(request, hooks, std::move(frames), request.output.empty() ? defaultOutputFor(withoutFrameToken(inputs[0])) : request.output,
                            inputs[0]);
    }
    // Several inputs none of which is DICOM (frames of a cache, scans):
    // each encoded alone, to the folder the output names or beside itself;
    // with an output NAME.ssvdag that is no folder, one sequence file.
    const bool several = inputs.size() > 1 && std::none_of(inputs.begin(), inputs.end(), [](const std::string& in) {
                             return bridge::denseFormatOf(in) == bridge::DenseFormat::Dicom;
                         });
    if (!several) {
        EncodeInputsRequest one = request;
        const std::string input = one.dense.takeInputs(inputs);  // several DICOM inputs: one set
        const std::string output = request.output.empty() ? defaultOutputFor(input) : request.output;
        EncodeResult result = encodeOne(one, hooks, input, output, hooks.file);
        EncodeInputsResult out;
        out.shape = EncodeShape::OneFile, out.written = result.written, out.output = output;
        out.report = std::move(result.report), out.threshold = result.threshold;
        return out;
    }
    if (lowerExtension(request.output) == ".ssvdag" && !std::filesystem::is_directory(request.output))
        return encodeFrames(request, hooks, framesOfList(inputs), request.output, std::to_string(inputs.size()) + " files");
    const std::vector<std::string> outputs = outputsForEach(inputs, request.output);
    EncodeInputsResult out;
    out.shape = EncodeShape::FileEach, out.output = request.output, out.report = nlohmann::json::array();
    for (size_t i = 0; i < inputs.size(); ++i) {
        EncodeResult result = encodeOne(request, hooks, inputs[i], outputs[i], hooks.file);
        if (!result.written) continue;  // another process of the team writes and reports
        out.written = true;
        if (hooks.onFile) hooks.onFile(result.report);
        out.report.push_back(std::move(result.report));
    }
    return out;
}

} // namespace vdbdag::app
