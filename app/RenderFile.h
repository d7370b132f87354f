// `vdbdag render` as a library call: traces an .ssvdag (or a .vdb, .nvdb or
// scan, encoded in memory first) without decompressing it, through a render
// backend the caller supplies (the CPU reference tracer, the Vulkan compute
// backend), and writes each frame's image (PNG or EXR, vdb_bridge/
// ImageWriter.h). Chooses the shading a grid wants (a dense scan as a volume
// or as labels, a scan in patient space head up), refuses every option that
// would not take effect, and frames every frame of a sequence from one
// camera: the first frame's.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/format/ReadLimits.h"
#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"

namespace vdbdag::app {

// What traces the frames (the command line's --backend makes one).
class RenderBackend {
public:
    virtual ~RenderBackend() = default;
    virtual std::string name() const = 0;
    // What ran the frames: the Vulkan device's name, or the CPU's thread count.
    virtual std::string device() const = 0;
    virtual trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                                trace::RenderStats& stats) = 0;
};

// The options of `vdbdag render --help`, as text where the command line
// takes text (--window 0,400; --labels 3,17; --slice z=40).
struct RenderRequest {
    std::string input, grid, camera, up = "y", view = "iso", shading = "auto", window, labels, iso, slice, tf;
    bool upGiven = false, viewGiven = false, densityScaleGiven = false;  // given, rather than defaults
    int width = 1024, height = 768, frames = 1;
    double fov = 35, lodPixels = 0, densityScale = 0.08;
    bool shadows = false, legend = false;
    format::ReadLimits limits;
};

// One image to make: a frame of a sequence file (its index and number) or
// the input whole, and where it goes.
struct RenderJob {
    std::optional<uint32_t> frameIndex;
    int64_t number = 0;
    std::string output;
};

struct RenderedImage {
    nlohmann::json report;  // as `render --json` prints it
    std::string text;       // the line `render` prints
};

struct RenderHooks {
    std::function<std::unique_ptr<RenderBackend>()> backend;  // a fresh backend for each job
    std::function<void(const std::string&)> note;             // what was chosen for the user (unset: dropped)
    std::function<void(const RenderedImage&)> onImage;        // each image as soon as it is written
};

// Renders each job in turn. Throws vdbdag::Error with one line on a
// refused option or input; an image is written atomically.
std::vector<RenderedImage> renderImages(const RenderRequest& request, const std::vector<RenderJob>& jobs, const RenderHooks& hooks);

} // namespace vdbdag::app
