// `vdbdag render IN.ssvdag -o OUT.png|OUT.exr [...]`: parses the request,
// picks the frames (app/FrameJobs.h) and the backend (the CPU reference
// tracer or Vulkan, cli/RenderBackend.h), runs app::renderImages
// (app/RenderFile.h) and prints rays/s and ms per frame.
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/RenderFile.h"
#include "cli/Commands.h"
#include "cli/FiniteNumber.h"
#include "app/FrameJobs.h"
#include "cli/GlobalOptions.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RenderBackend.h"
#include "cli/RunContext.h"
#include "src/format/FrameSequence.h"
#include "src/util/OutputPath.h"
#include "vdb_bridge/InputScene.h"

namespace vdbdag::cli {

void addRenderCommand(CLI::App& app, int& exitCode) {
    struct Options {
        app::RenderRequest request;
        std::string output, backend = "auto", frame;
        int device = -1;
        bool json = false, force = false;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<Options>();
    app::RenderRequest& r = opt->request;
    CLI::App* cmd = app.add_subcommand("render", "Trace an .ssvdag file without decompressing it and write an image");
    cmd->add_option("input", r.input, "input .ssvdag file (or a .vdb, .nvdb or scan, encoded in memory first)")->required();
    cmd->add_option("-o,--output", opt->output, "output image (.png: 8-bit sRGB; .exr: float colour, alpha, depth Z, normal N)")->required();
    cmd->add_option("--grid", r.grid, "grid to render (default: the first)");
    cmd->add_option("--width", r.width, "image width")->check(CLI::Range(1, 16384));
    cmd->add_option("--height", r.height, "image height")->check(CLI::Range(1, 16384));
    cmd->add_option("--camera", r.camera, "EYE,TARGET,UP as 9 comma-separated world coordinates (default: frame the grid)");
    cmd->add_option("--up", r.up, "the world's up axis for the default camera: x, y or z (scans and CAD models are often z-up)")
        ->check(CLI::IsMember({"x", "y", "z"}))
        ->capture_default_str();
    cmd->add_option("--view", r.view, "where the default camera looks from: iso (front-right-above), front, back, side or top")
        ->check(CLI::IsMember({"iso", "front", "back", "side", "top"}))
        ->capture_default_str();
    cmd->add_option("--shading", r.shading,
                    "auto (level sets as surfaces; fog volumes, by class or by content (densities >= 0, background 0), as fog; else voxels coloured by "
                    "value; a dense scan as volume, or as labels when it holds few integer values), fog, surface, values, mip (the largest value "
                    "along each ray, air transparent), labels (the first labelled voxel, a colour per label), iso (the surface where the value first "
                    "reaches --iso), volume (emission-absorption through a transfer function over --window) or slice (the voxels of --slice in "
                    "grey); mip, labels, iso, volume and slice on the CPU tracer")
        ->check(CLI::IsMember({"auto", "fog", "surface", "values", "mip", "labels", "iso", "volume", "slice"}))
        ->capture_default_str();
    cmd->add_option("--window", r.window,
                    "mip: LOW,HIGH, the values shown black to white (LOW and below transparent; default: Otsu's threshold of the pixels' "
                    "maxima to their 99.5th percentile); volume: LOW,HIGH, the transfer function's ramp (default: Otsu's threshold of the "
                    "values to their 99.5th percentile)");
    cmd->add_option("--tf", r.tf,
                    "volume: a transfer function file, a ParaView colour-map preset (JSON with \"RGBPoints\" and optional opacity \"Points\"), "
                    "instead of --window's ramp")
        ->check(CLI::ExistingFile);
    cmd->add_option("--labels", r.labels, "labels: the labels shown, e.g. 3,17 (default: every one but 0 and the background)");
    cmd->add_flag("--legend", r.legend,
                  "draw a colour bar with its range in the image's right margin (value shading, mip, slice and volume)");
    cmd->add_option("--slice", r.slice, "slice: AXIS=INDEX, the voxels shown (z=40: those of index z 40), seen along that axis unless --view/--up/--camera say");
    cmd->add_option("--iso", r.iso, "iso: the surface's value, e.g. 300 for a CT's bone (default: Otsu's threshold of the values, air against tissue)");
    cmd->add_option("--fov", r.fov, "vertical field of view in degrees")->check(finiteNumber())->check(CLI::Range(1.0, 170.0));
    cmd->add_option("--backend", opt->backend, "vulkan, cpu, or auto (a Vulkan GPU when there is one, else the CPU tracer; a software Vulkan device such as lavapipe only with --backend vulkan)")->check(CLI::IsMember({"auto", "vulkan", "cpu"}));
    cmd->add_option("--device", opt->device, "Vulkan device index (see `vdbdag devices`)");
    cmd->add_option("--lod-pixels", r.lodPixels, "stop descending where a node projects smaller than this many pixels (0: off)")->check(finiteNumber())->check(CLI::Range(0.0, 1e6));
    cmd->add_flag("--shadows", r.shadows, "cast a shadow ray towards the light");
    cmd->add_option("--density-scale", r.densityScale,
                    "fog: extinction per voxel length at the largest density (default: the scale at which the median optical depth of the "
                    "camera's rays through the fog is 1)")->check(finiteNumber())->check(CLI::Range(0.0, 1e6));
    cmd->add_option("--frames", r.frames, "render this many frames and report the median time")->check(CLI::Range(1, 1000));
    cmd->add_option("--frame", opt->frame,
                    "a sequence file: the frame to render (its number), or with a frame token in -o (f.####.png) the frames to render "
                    "(12, 10-20, 1,5,9-12; default: all), one image each, seen from one camera");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the report as JSON");
    opt->limits.add(*cmd);
    cmd->callback([opt, cmd, &exitCode] {
        app::RenderRequest request = opt->request;
        request.densityScaleGiven = cmd->count("--density-scale") > 0, request.upGiven = cmd->count("--up") > 0, request.viewGiven = cmd->count("--view") > 0;
        request.limits = opt->limits.limits(0);
        setActivity(request.input, "rendering");
        // The frames of a sequence file rendered: (index, output); else the
        // input whole to -o.
        const std::vector<app::FrameJob> jobs =
            app::frameJobs({request.input, opt->output, opt->frame, "--frame", "image", "render one with --frame N, or each to its image with a frame token in -o (f.####.png)"},
                      bridge::inputKindOf(request.input) == bridge::InputKind::Ssvdag ? std::optional(format::readFrameList(request.input)) : std::nullopt);
        std::vector<app::RenderJob> renderJobs;
        for (const app::FrameJob& job : jobs) {
            checkOutputPath(job.output, {request.input}, {{".png", ".exr"}, "render", opt->force});
            renderJobs.push_back({job.index, job.number, job.output});
        }
        app::RenderHooks hooks;
        hooks.backend = [opt] { return makeRenderBackend(opt->backend, opt->device); };
        hooks.note = [](const std::string& n) { note(n); };
        if (!opt->json) hooks.onImage = [](const app::RenderedImage& image) { fmt::print("{}", image.text); };
        const std::vector<app::RenderedImage> images = app::renderImages(request, renderJobs, hooks);
        if (opt->json) {
            nlohmann::json reports = nlohmann::json::array();
            for (const app::RenderedImage& image : images) reports.push_back(image.report);
            printJson(reports.size() == 1 ? reports[0] : reports);
        }
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
