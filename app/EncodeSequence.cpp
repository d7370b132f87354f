// See EncodeSequence.h.
#include "app/EncodeSequence.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include <fmt/core.h>

#include "src/format/FrameSequence.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "src/util/TemporaryFiles.h"

namespace vdbdag::app {
namespace {

// The team's frame reports, on the first process in frame order.
nlohmann::json gatherReports(pipeline::CubeTeam& team, nlohmann::json reports) {
    if (team.size() <= 1) return reports;
    const std::string mine = reports.dump();
    nlohmann::json all = nlohmann::json::array();
    for (const std::vector<uint8_t>& theirs : team.gather(std::vector<uint8_t>(mine.begin(), mine.end())))
        for (auto& r : nlohmann::json::parse(theirs.begin(), theirs.end())) all.push_back(std::move(r));
    std::sort(all.begin(), all.end(), [](const nlohmann::json& a, const nlohmann::json& b) { return a["frame_index"] < b["frame_index"]; });
    return all;
}

} // namespace

SequenceResult encodeSequence(const SequenceRequest& request, pipeline::CubeTeam& team, const EncodeFrame& encodeFrame) {
    namespace fs = std::filesystem;
    const auto start = std::chrono::steady_clock::now();
    const std::vector<FrameFile>& frames = request.frames;
    if (frames.empty()) throw Error(request.described + ": no frame to encode");
    const std::string& output = request.output;
    std::vector<std::string> inputs;
    for (const FrameFile& f : frames) inputs.push_back(f.path);
    checkOutputPath(output, inputs, {{".ssvdag"}, "encode", request.force});
    const fs::path near = request.scratch.empty() ? fs::path(output) : fs::path(request.scratch) / fs::path(output).filename();
    std::string folder = team.isRoot() ? temporaryNameFor(near.string()) : std::string();
    std::optional<TemporaryGuard> guard;
    struct Removed {
        std::string path;
        ~Removed() {
            std::error_code ignored;
            if (!path.empty()) fs::remove_all(path, ignored);
        }
    } removed;
    if (team.isRoot()) {
        guard.emplace(folder, /*folder=*/true);
        removed.path = folder;
        std::error_code ec;
        if (!fs::create_directory(folder, ec) || ec)
            throw Error(folder + ": cannot make the folder for the frames being encoded (" + (ec ? ec.message() : "it exists") + ")");
    }
    if (team.size() > 1) {  // (after process 0 made it)
        const std::vector<uint8_t> name = team.broadcast(std::vector<uint8_t>(folder.begin(), folder.end()));
        folder.assign(name.begin(), name.end());
    }
    Progress progress("encode " + fs::path(output).filename().string(), frames.size() * 1000);
    const bool wasQuiet = isQuiet();
    setQuiet(true);  // the frames' own progress lines
    struct Restore {
        bool quiet;
        ~Restore() { setQuiet(quiet); }
    } restore{wasQuiet};
    std::vector<format::FramePart> parts;
    nlohmann::json reports = nlohmann::json::array();
    for (size_t i = 0; i < frames.size(); ++i) {
        parts.push_back({frames[i].number, (fs::path(folder) / fmt::format("frame{:06}.ssvdag", i)).string()});
        if (i % team.size() != team.rank()) continue;
        progress.setLabel(fmt::format("encode frame {} ({} of {})", frames[i].number, i + 1, frames.size()));
        reports.push_back(encodeFrame(i, frames[i].path, parts.back().path, [&progress, i](double done) { progress.set(i * 1000 + uint64_t(done * 1000)); }));
        reports.back()["frame_index"] = i;
    }
    reports = gatherReports(team, std::move(reports));  // every process's, once its frames are written
    SequenceResult result;
    if (!team.isRoot()) return result;
    progress.setLabel("encode: writing " + output);
    uint64_t bytes = 0;
    writeStreamAtomically(output, [&](std::ostream& out) { bytes = format::writeSequence(parts, out); });
    progress.finish();
    uint64_t frameBytes = 0, voxels = 0;
    for (const auto& r : reports) {
        frameBytes += r["bytes"].get<uint64_t>();
        voxels += r["active_voxels"].get<uint64_t>();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.report = {{"input", request.described}, {"output", output}, {"bytes", bytes}, {"ssvdag_bytes", bytes}, {"frames", frames.size()},
                     {"first_frame", frames.front().number}, {"last_frame", frames.back().number}, {"frame_files_bytes", frameBytes},
                     {"active_voxels", voxels}, {"seconds", seconds}, {"bits_per_active_voxel", voxels ? 8.0 * double(bytes) / double(voxels) : 0.0}};
    for (size_t i = 0; i < reports.size(); ++i) {
        reports[i]["frame"] = frames[i].number;
        reports[i]["output"] = output;
        reports[i].erase("frame_index");
    }
    result.report["per_frame"] = reports;
    result.written = true;
    return result;
}

} // namespace vdbdag::app
