// See RenderFile.h.
#include "app/RenderFile.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <unordered_set>

#include <fmt/core.h>

#include "src/format/DagBounds.h"
#include "src/format/SsvdagFile.h"
#include "src/trace/FogDensity.h"
#include "src/trace/Legend.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/SliceView.h"
#include "src/util/Error.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/ImageWriter.h"
#include "vdb_bridge/InputScene.h"
#include "vdb_bridge/VdbSummary.h"

namespace vdbdag::app {
namespace {

std::vector<double> parseNumbers(const std::string& text, size_t count, const std::string& what) {
    std::vector<double> values;
    std::stringstream stream(text);
    std::string item;
    while (std::getline(stream, item, ',')) {
        try {
            size_t used = 0;
            values.push_back(std::stod(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw Error(what + ": '" + item + "' is not a number");
        }
        if (!std::isfinite(values.back())) throw Error(what + ": values must be finite");
    }
    if (values.size() != count) throw Error(what + ": expected " + std::to_string(count) + " comma-separated numbers, got " + std::to_string(values.size()));
    return values;
}

// An integer or float grid, neither a level set nor a fog, whose every voxel
// of its bounding box is active (at least 16^3 of them): a scan.
bool denseScalarScan(const format::EncodedGrid& grid) {
    const ValueType t = grid.record.valueType;
    if (t != ValueType::Int32 && t != ValueType::Int64 && t != ValueType::Float && t != ValueType::Double) return false;
    if (grid.record.gridClass == "level set" || grid.record.gridClass == "fog volume") return false;
    const std::optional<format::IndexBox> box = format::dagBounds(grid.active.dag);
    if (!box || grid.active.voxels < 4096) return false;
    uint64_t volume = 1;
    for (int a = 0; a < 3; ++a) volume *= uint64_t(box->max[size_t(a)] - box->min[size_t(a)] + 1);
    return volume == grid.active.voxels;
}

// An integer grid of at most 256 distinct values (an atlas, a
// segmentation), 0 among them, in regions: at least 3/5 of its entries
// other than 0 repeat the entry before (in attribute order, mostly a
// neighbour), as a label's region does and an 8-bit scan does not (a CT or
// MR in bytes also has at most 256 values, 0 among them; in raster order
// the shared atlases repeat 0.75-0.98, the 8-bit scans 0.03-0.49).
// From the decoded values (a grid read whole); false when there are none.
bool looksLikeLabels(const format::EncodedGrid& grid) {
    const unsigned vs = grid.record.valueType == ValueType::Int32 ? 4 : grid.record.valueType == ValueType::Int64 ? 8 : 0;
    if (!vs || grid.active.attributes.empty()) return false;
    std::unordered_set<int64_t> seen;
    uint64_t labelled = 0, repeats = 0;
    int64_t before = 0;
    for (size_t at = 0; at + vs <= grid.active.attributes.size(); at += vs) {
        int64_t v = 0;
        if (vs == 4) {
            int32_t w;
            std::memcpy(&w, grid.active.attributes.data() + at, 4);
            v = w;
        } else {
            std::memcpy(&v, grid.active.attributes.data() + at, 8);
        }
        if (seen.insert(v).second && seen.size() > 256) return false;
        if (v != 0) labelled += 1, repeats += at > 0 && v == before;
        before = v;
    }
    return seen.count(0) > 0 && repeats * 5 >= labelled * 3;
}

} // namespace

std::vector<RenderedImage> renderImages(const RenderRequest& request, const std::vector<RenderJob>& jobs, const RenderHooks& userHooks) {
    RenderHooks hooks = userHooks;
    if (!hooks.note) hooks.note = [](const std::string&) {};
    format::ReadOptions readOptions;
    readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
    readOptions.limits = request.limits;            // traced where it lies, compressed
    // One camera (and fog density) for every frame: the first frame's.
    std::optional<trace::Camera> sharedCamera;
    std::optional<double> sharedDensity;
    std::vector<RenderedImage> images;
    for (const RenderJob& job : jobs) {
        const std::string& output = job.output;
        readOptions.frame = job.frameIndex;
        // A .vdb, .nvdb or scan is encoded in memory first, as `encode` would.
        const format::SsvdagScene scene = bridge::sceneOfInput(request.input, readOptions);
        const format::EncodedGrid* chosen = nullptr;
        for (const format::EncodedGrid& g : scene.grids)
            if (request.grid.empty() || g.record.name == request.grid) { chosen = &g; break; }
        if (!chosen) throw Error(request.input + ": no grid named '" + request.grid + "'");
        if (chosen->active.dag.empty()) throw Error(request.input + ": grid '" + chosen->record.name + "' is empty: nothing to render");
        trace::Shading shading = trace::parseShading(request.shading);
        // A dense scan (every voxel of its box active: a CT's air too) shown
        // as voxel blocks is an opaque box: by default it is volume rendered
        // (VolumeRender.h), its air transparent, or shown as labels.
        if (shading == trace::Shading::Auto && denseScalarScan(*chosen)) {
            shading = looksLikeLabels(*chosen) ? trace::Shading::Labels : trace::Shading::Volume;
            hooks.note("grid '" + chosen->record.name + "' is a dense scan: shown as " +
                 (shading == trace::Shading::Labels ? std::string("labels, a colour each") : std::string("a volume, air transparent")) +
                 " (--shading mip, iso or values for the others)");
        }
        const trace::RenderGrid grid = trace::makeRenderGrid(*chosen, shading);
        // Every option takes effect or is refused.
        if (request.densityScaleGiven && !grid.fog)
            throw Error(request.input + ": --density-scale applies to fog shading, and grid '" + chosen->record.name + "' is shown as " +
                        trace::shadingOf(grid) + " (use --shading fog)");
        if (!request.window.empty() && !grid.mip && !grid.volume && !grid.slice) throw Error(request.input + ": --window applies to --shading mip, volume and slice");
        if (!request.slice.empty() && !grid.slice) throw Error(request.input + ": --slice applies to --shading slice");
        if (!request.tf.empty() && !grid.volume) throw Error(request.input + ": --tf applies to --shading volume");
        if (!request.tf.empty() && !request.window.empty()) throw Error(request.input + ": --tf and --window both set the transfer function: give one");
        if (request.legend && !trace::legendScale(grid, std::pair{0.0, 1.0}))
            throw Error(request.input + ": --legend applies to value shading, mip, slice and volume, and grid '" + chosen->record.name + "' is shown as " +
                        trace::shadingOf(grid));
        if (grid.slice && request.slice.empty()) throw Error(request.input + ": --shading slice needs --slice AXIS=INDEX (e.g. z=40)");
        const std::optional<trace::SlicePlane> slicePlane = grid.slice ? std::optional(trace::parseSlicePlane(request.slice)) : std::nullopt;
        if (!request.labels.empty() && !grid.labels) throw Error(request.input + ": --labels applies to --shading labels");
        if (!request.iso.empty() && !grid.iso) throw Error(request.input + ": --iso applies to --shading iso");
        if ((grid.volume || grid.mip || grid.slice || grid.labels || grid.iso) && request.shadows) throw Error(request.input + ": --shadows applies to surfaces, not to --shading " + trace::shadingOf(grid));
        if (request.shadows && grid.fog)
            throw Error(request.input + ": --shadows applies to surfaces; grid '" + chosen->record.name + "' is shown as fog, which has no shadows yet");
        if (!request.camera.empty() && (request.upGiven || request.viewGiven)) throw Error("--camera sets the view itself: give --up and --view without it");
        const trace::GridFrame frame(grid.indexToWorld);
        trace::ViewSpec view{trace::parseUpAxis(request.up), trace::parseView(request.view)};
        // A scan in patient space (LPS: x left, y posterior, z superior; RAS
        // flips x and y) is shown head up from the front unless told otherwise.
        if (slicePlane && !request.upGiven && !request.viewGiven && request.camera.empty()) {
            view = {slicePlane->axis, trace::View::Top};  // straight along the slice's axis
        } else if (!request.upGiven && !request.viewGiven && request.camera.empty())
            if (const std::optional<bridge::ScanProvenance> scan = bridge::scanProvenanceOf(chosen->record); scan && (scan->space == "LPS" || scan->space == "RAS")) {
                view = {2, scan->space == "LPS" ? trace::View::Front : trace::View::Back};
                hooks.note("grid '" + chosen->record.name + "' is a scan in " + scan->space + " space: shown head up, from the front (--up/--view to change)");
            }
        trace::Camera camera = sharedCamera ? *sharedCamera : trace::frameBounds(frame, grid.cellLo, grid.cellHi, request.width, request.height, request.fov, view);
        if (!request.camera.empty()) {
            const auto v = parseNumbers(request.camera, 9, "--camera");
            camera.eye = {v[0], v[1], v[2]};
            camera.target = {v[3], v[4], v[5]};
            camera.up = {v[6], v[7], v[8]};
            if (glm::length(camera.target - camera.eye) == 0 || glm::length(glm::cross(camera.target - camera.eye, camera.up)) == 0)
                throw Error("--camera: the eye must differ from the target and UP must not be parallel to the view direction");
        }
        trace::RenderOptions options;
        options.lodPixels = request.lodPixels;
        options.shadows = request.shadows;
        options.densityScale = request.densityScaleGiven || !grid.fog ? request.densityScale
                               : sharedDensity                   ? *sharedDensity
                                                                 : trace::autoDensityScale(grid, camera, request.densityScale);
        sharedCamera = camera;
        sharedDensity = options.densityScale;

        if (slicePlane) options.slice = *slicePlane;
        if ((grid.mip || grid.volume || grid.slice) && !request.window.empty()) {  // else the renderer chooses it from the image (RenderStats::window)
            const auto w = parseNumbers(request.window, 2, "--window");
            if (!(w[1] > w[0])) throw Error("--window: HIGH must be greater than LOW");
            options.window = std::pair{w[0], w[1]};
        }
        if (grid.volume && !request.tf.empty()) options.transfer = trace::readTransferFunction(request.tf);
        if (grid.iso && !request.iso.empty()) options.iso = parseNumbers(request.iso, 1, "--iso")[0];
        if (grid.labels && !request.labels.empty())
            for (const double l : parseNumbers(request.labels, size_t(std::count(request.labels.begin(), request.labels.end(), ',') + 1), "--labels")) {
                if (l != std::trunc(l)) throw Error("--labels: " + std::to_string(l) + " is not an integer");
                options.labels.push_back(int64_t(l));
            }
        std::unique_ptr<RenderBackend> backend = hooks.backend();
        std::vector<double> times;
        trace::Image image;
        trace::RenderStats stats;
        for (int f = 0; f < request.frames; ++f) {
            image = backend->render(grid, camera, options, stats);
            times.push_back(stats.milliseconds);
        }
        std::sort(times.begin(), times.end());
        const double ms = times[times.size() / 2];
        if (request.legend) {
            trace::LegendScale scale = *trace::legendScale(grid, stats.window, options.transfer ? &*options.transfer : nullptr);
            std::vector<std::pair<std::string, std::string>> metadata;
            for (const bridge::MetadataEntry& m : bridge::gridHeaderFacts(chosen->record, std::nullopt, request.input).metadata) metadata.emplace_back(m.name, m.value);
            scale.units = trace::valueUnits(metadata);
            trace::drawLegend(image, scale);
        }
        bridge::writeImage(output, image);
        const double raysPerSecond = double(stats.primaryRays + stats.secondaryRays) / (ms / 1000.0);
        RenderedImage out;
        out.report = {{"input", request.input},       {"output", output},          {"grid", chosen->record.name},
                      {"backend", backend->name()}, {"device", backend->device()}, {"width", request.width},           {"height", request.height},
                      {"frames", request.frames},      {"ms_per_frame", ms},            {"ms_min", times.front()},
                      {"ms_max", times.back()},     {"primary_rays", stats.primaryRays}, {"secondary_rays", stats.secondaryRays},
                      {"rays_per_second", raysPerSecond}, {"lod_pixels", request.lodPixels}, {"shadows", request.shadows},
                      {"shading", trace::shadingOf(grid)}, {"density_scale", grid.fog ? nlohmann::json(options.densityScale) : nlohmann::json()},
                      {"window", stats.window ? nlohmann::json({stats.window->first, stats.window->second}) : nlohmann::json()},
                      {"iso", stats.iso ? nlohmann::json(*stats.iso) : nlohmann::json()},
                      {"camera", {{"eye", {camera.eye.x, camera.eye.y, camera.eye.z}}, {"target", {camera.target.x, camera.target.y, camera.target.z}},
                                  {"up", {camera.up.x, camera.up.y, camera.up.z}}}}};
        if (job.frameIndex) out.report["frame"] = job.number;
        out.text = fmt::format("render '{}' ({}x{}) on {} ({}): {:.1f} ms per frame (median of {}), {:.2f} M rays/s ({} primary, {} shadow) -> {}\n",
                               chosen->record.name, request.width, request.height, backend->name(), backend->device(), ms, request.frames,
                               raysPerSecond / 1e6, stats.primaryRays, stats.secondaryRays, output);
        if (hooks.onImage) hooks.onImage(out);
        images.push_back(std::move(out));
    }
    return images;
}

} // namespace vdbdag::app
