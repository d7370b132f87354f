// `vdbdag render IN.ssvdag -o OUT.png|OUT.exr [...]`: traces the compressed
// DAG directly (CPU reference tracer or the Vulkan backend) and writes the
// frame through OpenImageIO; prints rays/s and ms per frame.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <optional>
#include <unordered_set>
#include <cmath>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/FrameJobs.h"
#include "cli/GlobalOptions.h"
#include "cli/JsonReport.h"
#include "cli/RunContext.h"
#include "cli/FiniteNumber.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RenderBackend.h"
#include "src/format/SsvdagFile.h"
#include "src/format/DagBounds.h"
#include "src/trace/FogDensity.h"
#include "src/trace/Camera.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Legend.h"
#include "src/trace/SliceView.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/ImageWriter.h"
#include "vdb_bridge/InputScene.h"
#include "src/format/FrameSequence.h"
#include "vdb_bridge/VdbSummary.h"

namespace vdbdag::cli {
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
    const std::optional<format::IndexBox> box = format::dagBounds(grid.dag);
    if (!box || grid.activeVoxels < 4096) return false;
    uint64_t volume = 1;
    for (int a = 0; a < 3; ++a) volume *= uint64_t(box->max[size_t(a)] - box->min[size_t(a)] + 1);
    return volume == grid.activeVoxels;
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
    if (!vs || grid.attributes.empty()) return false;
    std::unordered_set<int64_t> seen;
    uint64_t labelled = 0, repeats = 0;
    int64_t before = 0;
    for (size_t at = 0; at + vs <= grid.attributes.size(); at += vs) {
        int64_t v = 0;
        if (vs == 4) {
            int32_t w;
            std::memcpy(&w, grid.attributes.data() + at, 4);
            v = w;
        } else {
            std::memcpy(&v, grid.attributes.data() + at, 8);
        }
        if (seen.insert(v).second && seen.size() > 256) return false;
        if (v != 0) labelled += 1, repeats += at > 0 && v == before;
        before = v;
    }
    return seen.count(0) > 0 && repeats * 5 >= labelled * 3;
}

} // namespace

void addRenderCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output, grid, camera, backend = "auto", up = "y", view = "iso", shading = "auto", window, labels, iso, slice, tf, frame;
        int width = 1024, height = 768, frames = 1, device = -1;
        double fov = 35, lodPixels = 0, densityScale = 0.08;
        bool shadows = false, json = false, force = false, legend = false;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("render", "Trace an .ssvdag file without decompressing it and write an image");
    cmd->add_option("input", opt->input, "input .ssvdag file (or a .vdb, .nvdb or scan, encoded in memory first)")->required();
    cmd->add_option("-o,--output", opt->output, "output image (.png: 8-bit sRGB; .exr: float colour, alpha, depth Z, normal N)")->required();
    cmd->add_option("--grid", opt->grid, "grid to render (default: the first)");
    cmd->add_option("--width", opt->width, "image width")->check(CLI::Range(1, 16384));
    cmd->add_option("--height", opt->height, "image height")->check(CLI::Range(1, 16384));
    cmd->add_option("--camera", opt->camera, "EYE,TARGET,UP as 9 comma-separated world coordinates (default: frame the grid)");
    cmd->add_option("--up", opt->up, "the world's up axis for the default camera: x, y or z (scans and CAD models are often z-up)")
        ->check(CLI::IsMember({"x", "y", "z"}))
        ->capture_default_str();
    cmd->add_option("--view", opt->view, "where the default camera looks from: iso (front-right-above), front, back, side or top")
        ->check(CLI::IsMember({"iso", "front", "back", "side", "top"}))
        ->capture_default_str();
    cmd->add_option("--shading", opt->shading,
                    "auto (level sets as surfaces; fog volumes, by class or by content (densities >= 0, background 0), as fog; else voxels coloured by "
                    "value; a dense scan as volume, or as labels when it holds few integer values), fog, surface, values, mip (the largest value "
                    "along each ray, air transparent), labels (the first labelled voxel, a colour per label), iso (the surface where the value first "
                    "reaches --iso), volume (emission-absorption through a transfer function over --window) or slice (the voxels of --slice in "
                    "grey); mip, labels, iso, volume and slice on the CPU tracer")
        ->check(CLI::IsMember({"auto", "fog", "surface", "values", "mip", "labels", "iso", "volume", "slice"}))
        ->capture_default_str();
    cmd->add_option("--window", opt->window,
                    "mip: LOW,HIGH, the values shown black to white (LOW and below transparent; default: Otsu's threshold of the pixels' "
                    "maxima to their 99.5th percentile); volume: LOW,HIGH, the transfer function's ramp (default: Otsu's threshold of the "
                    "values to their 99.5th percentile)");
    cmd->add_option("--tf", opt->tf,
                    "volume: a transfer function file, a ParaView colour-map preset (JSON with \"RGBPoints\" and optional opacity \"Points\"), "
                    "instead of --window's ramp")
        ->check(CLI::ExistingFile);
    cmd->add_option("--labels", opt->labels, "labels: the labels shown, e.g. 3,17 (default: every one but 0 and the background)");
    cmd->add_flag("--legend", opt->legend,
                  "draw a colour bar with its range in the image's right margin (value shading, mip, slice and volume)");
    cmd->add_option("--slice", opt->slice, "slice: AXIS=INDEX, the voxels shown (z=40: those of index z 40), seen along that axis unless --view/--up/--camera say");
    cmd->add_option("--iso", opt->iso, "iso: the surface's value, e.g. 300 for a CT's bone (default: Otsu's threshold of the values, air against tissue)");
    cmd->add_option("--fov", opt->fov, "vertical field of view in degrees")->check(finiteNumber())->check(CLI::Range(1.0, 170.0));
    cmd->add_option("--backend", opt->backend, "vulkan, cpu, or auto (a Vulkan GPU when there is one, else the CPU tracer; a software Vulkan device such as lavapipe only with --backend vulkan)")->check(CLI::IsMember({"auto", "vulkan", "cpu"}));
    cmd->add_option("--device", opt->device, "Vulkan device index (see `vdbdag devices`)");
    cmd->add_option("--lod-pixels", opt->lodPixels, "stop descending where a node projects smaller than this many pixels (0: off)")->check(finiteNumber())->check(CLI::Range(0.0, 1e6));
    cmd->add_flag("--shadows", opt->shadows, "cast a shadow ray towards the light");
    cmd->add_option("--density-scale", opt->densityScale,
                    "fog: extinction per voxel length at the largest density (default: the scale at which the median optical depth of the "
                    "camera's rays through the fog is 1)")->check(finiteNumber())->check(CLI::Range(0.0, 1e6));
    cmd->add_option("--frames", opt->frames, "render this many frames and report the median time")->check(CLI::Range(1, 1000));
    cmd->add_option("--frame", opt->frame,
                    "a sequence file: the frame to render (its number), or with a frame token in -o (f.####.png) the frames to render "
                    "(12, 10-20, 1,5,9-12; default: all), one image each, seen from one camera");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the report as JSON");
    opt->limits.add(*cmd);
    cmd->callback([opt, cmd, &exitCode] {
        const bool cmdDensityScaleGiven = cmd->count("--density-scale") > 0, cmdUpGiven = cmd->count("--up") > 0, cmdViewGiven = cmd->count("--view") > 0;
        setActivity(opt->input, "rendering");
        format::ReadOptions readOptions;
        readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
        readOptions.limits = opt->limits.limits(0);  // traced where it lies, compressed
        // The frames of a sequence file rendered: (index, output); else the
        // input whole to -o.
        const std::vector<FrameJob> jobs =
            frameJobs({opt->input, opt->output, opt->frame, "--frame", "image", "render one with --frame N, or each to its image with a frame token in -o (f.####.png)"},
                      bridge::inputKindOf(opt->input) == bridge::InputKind::Ssvdag ? std::optional(format::readFrameList(opt->input)) : std::nullopt);
        for (const FrameJob& job : jobs) checkOutputPath(job.output, {opt->input}, {{".png", ".exr"}, "render", opt->force});
        // One camera (and fog density) for every frame: the first frame's.
        std::optional<trace::Camera> sharedCamera;
        std::optional<double> sharedDensity;
        nlohmann::json reports = nlohmann::json::array();
        for (const FrameJob& job : jobs) {
            const std::string& output = job.output;
            readOptions.frame = job.index;
            // A .vdb, .nvdb or scan is encoded in memory first, as `encode` would.
            const format::SsvdagScene scene = bridge::sceneOfInput(opt->input, readOptions);
            const format::EncodedGrid* chosen = nullptr;
            for (const format::EncodedGrid& g : scene.grids)
                if (opt->grid.empty() || g.record.name == opt->grid) { chosen = &g; break; }
            if (!chosen) throw Error(opt->input + ": no grid named '" + opt->grid + "'");
            if (chosen->dag.empty()) throw Error(opt->input + ": grid '" + chosen->record.name + "' is empty: nothing to render");
            trace::Shading shading = trace::parseShading(opt->shading);
            // A dense scan (every voxel of its box active: a CT's air too) shown
            // as voxel blocks is an opaque box: by default it is volume rendered
            // (VolumeRender.h), its air transparent, or shown as labels.
            if (shading == trace::Shading::Auto && denseScalarScan(*chosen)) {
                shading = looksLikeLabels(*chosen) ? trace::Shading::Labels : trace::Shading::Volume;
                note("grid '" + chosen->record.name + "' is a dense scan: shown as " +
                     (shading == trace::Shading::Labels ? std::string("labels, a colour each") : std::string("a volume, air transparent")) +
                     " (--shading mip, iso or values for the others)");
            }
            const trace::RenderGrid grid = trace::makeRenderGrid(*chosen, shading);
            // Every option takes effect or is refused.
            if (cmdDensityScaleGiven && !grid.fog)
                throw Error(opt->input + ": --density-scale applies to fog shading, and grid '" + chosen->record.name + "' is shown as " +
                            trace::shadingOf(grid) + " (use --shading fog)");
            if (!opt->window.empty() && !grid.mip && !grid.volume && !grid.slice) throw Error(opt->input + ": --window applies to --shading mip, volume and slice");
            if (!opt->slice.empty() && !grid.slice) throw Error(opt->input + ": --slice applies to --shading slice");
            if (!opt->tf.empty() && !grid.volume) throw Error(opt->input + ": --tf applies to --shading volume");
            if (!opt->tf.empty() && !opt->window.empty()) throw Error(opt->input + ": --tf and --window both set the transfer function: give one");
            if (opt->legend && !trace::legendScale(grid, std::pair{0.0, 1.0}))
                throw Error(opt->input + ": --legend applies to value shading, mip, slice and volume, and grid '" + chosen->record.name + "' is shown as " +
                            trace::shadingOf(grid));
            if (grid.slice && opt->slice.empty()) throw Error(opt->input + ": --shading slice needs --slice AXIS=INDEX (e.g. z=40)");
            const std::optional<trace::SlicePlane> slicePlane = grid.slice ? std::optional(trace::parseSlicePlane(opt->slice)) : std::nullopt;
            if (!opt->labels.empty() && !grid.labels) throw Error(opt->input + ": --labels applies to --shading labels");
            if (!opt->iso.empty() && !grid.iso) throw Error(opt->input + ": --iso applies to --shading iso");
            if ((grid.volume || grid.mip || grid.slice || grid.labels || grid.iso) && opt->shadows) throw Error(opt->input + ": --shadows applies to surfaces, not to --shading " + trace::shadingOf(grid));
            if (opt->shadows && grid.fog)
                throw Error(opt->input + ": --shadows applies to surfaces; grid '" + chosen->record.name + "' is shown as fog, which has no shadows yet");
            if (!opt->camera.empty() && (cmdUpGiven || cmdViewGiven)) throw Error("--camera sets the view itself: give --up and --view without it");
            const trace::GridFrame frame(grid.indexToWorld);
            trace::ViewSpec view{trace::parseUpAxis(opt->up), trace::parseView(opt->view)};
            // A scan in patient space (LPS: x left, y posterior, z superior; RAS
            // flips x and y) is shown head up from the front unless told otherwise.
            if (slicePlane && !cmdUpGiven && !cmdViewGiven && opt->camera.empty()) {
                view = {slicePlane->axis, trace::View::Top};  // straight along the slice's axis
            } else if (!cmdUpGiven && !cmdViewGiven && opt->camera.empty())
                if (const std::optional<bridge::ScanProvenance> scan = bridge::scanProvenanceOf(chosen->record); scan && (scan->space == "LPS" || scan->space == "RAS")) {
                    view = {2, scan->space == "LPS" ? trace::View::Front : trace::View::Back};
                    note("grid '" + chosen->record.name + "' is a scan in " + scan->space + " space: shown head up, from the front (--up/--view to change)");
                }
            trace::Camera camera = sharedCamera ? *sharedCamera : trace::frameBounds(frame, grid.cellLo, grid.cellHi, opt->width, opt->height, opt->fov, view);
            if (!opt->camera.empty()) {
                const auto v = parseNumbers(opt->camera, 9, "--camera");
                camera.eye = {v[0], v[1], v[2]};
                camera.target = {v[3], v[4], v[5]};
                camera.up = {v[6], v[7], v[8]};
                if (glm::length(camera.target - camera.eye) == 0 || glm::length(glm::cross(camera.target - camera.eye, camera.up)) == 0)
                    throw Error("--camera: the eye must differ from the target and UP must not be parallel to the view direction");
            }
            trace::RenderOptions options;
            options.lodPixels = opt->lodPixels;
            options.shadows = opt->shadows;
            options.densityScale = cmdDensityScaleGiven || !grid.fog ? opt->densityScale
                                   : sharedDensity                   ? *sharedDensity
                                                                     : trace::autoDensityScale(grid, camera, opt->densityScale);
            sharedCamera = camera;
            sharedDensity = options.densityScale;

            if (slicePlane) options.slice = *slicePlane;
            if ((grid.mip || grid.volume || grid.slice) && !opt->window.empty()) {  // else the renderer chooses it from the image (RenderStats::window)
                const auto w = parseNumbers(opt->window, 2, "--window");
                if (!(w[1] > w[0])) throw Error("--window: HIGH must be greater than LOW");
                options.window = std::pair{w[0], w[1]};
            }
            if (grid.volume && !opt->tf.empty()) options.transfer = trace::readTransferFunction(opt->tf);
            if (grid.iso && !opt->iso.empty()) options.iso = parseNumbers(opt->iso, 1, "--iso")[0];
            if (grid.labels && !opt->labels.empty())
                for (const double l : parseNumbers(opt->labels, size_t(std::count(opt->labels.begin(), opt->labels.end(), ',') + 1), "--labels")) {
                    if (l != std::trunc(l)) throw Error("--labels: " + std::to_string(l) + " is not an integer");
                    options.labels.push_back(int64_t(l));
                }
            auto backend = makeRenderBackend(opt->backend, opt->device);
            std::vector<double> times;
            trace::Image image;
            trace::RenderStats stats;
            for (int f = 0; f < opt->frames; ++f) {
                image = backend->render(grid, camera, options, stats);
                times.push_back(stats.milliseconds);
            }
            std::sort(times.begin(), times.end());
            const double ms = times[times.size() / 2];
            if (opt->legend) {
                trace::LegendScale scale = *trace::legendScale(grid, stats.window, options.transfer ? &*options.transfer : nullptr);
                std::vector<std::pair<std::string, std::string>> metadata;
                for (const bridge::MetadataEntry& m : bridge::gridHeaderFacts(chosen->record, std::nullopt, opt->input).metadata) metadata.emplace_back(m.name, m.value);
                scale.units = trace::valueUnits(metadata);
                trace::drawLegend(image, scale);
            }
            bridge::writeImage(output, image);
            const double raysPerSecond = double(stats.primaryRays + stats.secondaryRays) / (ms / 1000.0);
            if (opt->json) {
                nlohmann::json j{{"input", opt->input},       {"output", output},          {"grid", chosen->record.name},
                                 {"backend", backend->name()}, {"device", backend->device()}, {"width", opt->width},           {"height", opt->height},
                                 {"frames", opt->frames},      {"ms_per_frame", ms},            {"ms_min", times.front()},
                                 {"ms_max", times.back()},     {"primary_rays", stats.primaryRays}, {"secondary_rays", stats.secondaryRays},
                                 {"rays_per_second", raysPerSecond}, {"lod_pixels", opt->lodPixels}, {"shadows", opt->shadows},
                                 {"shading", trace::shadingOf(grid)}, {"density_scale", grid.fog ? nlohmann::json(options.densityScale) : nlohmann::json()},
                                 {"window", stats.window ? nlohmann::json({stats.window->first, stats.window->second}) : nlohmann::json()},
                                 {"iso", stats.iso ? nlohmann::json(*stats.iso) : nlohmann::json()},
                                 {"camera", {{"eye", {camera.eye.x, camera.eye.y, camera.eye.z}}, {"target", {camera.target.x, camera.target.y, camera.target.z}},
                                             {"up", {camera.up.x, camera.up.y, camera.up.z}}}}};
                if (job.index) j["frame"] = job.number;
                if (jobs.size() > 1) reports.push_back(std::move(j));
                else printJson(j);
            } else {
                fmt::print("render '{}' ({}x{}) on {} ({}): {:.1f} ms per frame (median of {}), {:.2f} M rays/s ({} primary, {} shadow) -> {}\n",
                           chosen->record.name, opt->width, opt->height, backend->name(), backend->device(), ms, opt->frames, raysPerSecond / 1e6,
                           stats.primaryRays, stats.secondaryRays, output);
            }
        }
        if (opt->json && jobs.size() > 1) printJson(reports);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
