// The Vulkan tracer: gpu/shaders/trace.comp, a port of the CPU reference
// tracer (src/trace/DagTracer, SurfaceHit, CpuRenderer), run as a compute
// shader straight over the compact SSVDAG (SSVDAG paper §5).
//
// The grid is uploaded once: the DAG's 16-bit inner words and 64-bit leaves,
// and the sections of its palette channels (DevicePaletteChannel: the values,
// and the ONV normal codes when the grid stores normals), each as a
// DeviceArray reached by buffer device address (no 128 MiB binding limit);
// the level table, offset widths, root corner, occupied box and ONV bit
// count and source go into a small parameter buffer. Pipelines are
// specialised for what the grid has (value type, level set, fog, colouring,
// shadows, stored normals) and cached.
//
// Contract (tests/unit/test_vulkan_tracer.cpp): for the same ray, traceHits
// returns exactly what DagTracer::trace (FirstHit) or firstSurfaceHit
// (Surface) returns - hit flag, voxel, t (bit-identical), attribute, face -
// and render() the image renderCpu() makes, up to the fog's exp().
//
// This header exposes no Vulkan type, so the CLI can include it.
#pragma once
#include <map>
#include <memory>
#include <span>
#include <vector>

#include "gpu/DeviceInfo.h"
#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::gpu {

class VulkanContext;
class DeviceBuffer;

enum class HitKind {
    FirstHit,  // DagTracer::trace: the first occupied voxel, tile or LOD node
    Surface,   // firstSurfaceHit: for level sets the first box with value <= 0
};

class VulkanTracer {
public:
    // Uploads `grid` (its dag and values must outlive the tracer) to the
    // device of `context` (which must outlive the tracer too). `chunkShift`
    // > 0 splits every array into chunks of 2^chunkShift bytes (tests of the
    // multi-chunk path, which DAGs beyond one allocation take); 0 = the device's largest.
    VulkanTracer(VulkanContext& context, const trace::RenderGrid& grid, uint32_t chunkShift = 0);
    // The same on a context of its own (`--device N`); throws the context's
    // one-line vdbdag::Error when no usable device exists.
    VulkanTracer(const ContextOptions& options, const trace::RenderGrid& grid);
    ~VulkanTracer();
    VulkanTracer(const VulkanTracer&) = delete;
    VulkanTracer& operator=(const VulkanTracer&) = delete;

    // Traces cell-space rays (Ray.h); `lodScale` as TraceOptions::lodScale.
    std::vector<trace::RayHit> traceHits(std::span<const trace::Ray> rays, HitKind kind = HitKind::FirstHit, double lodScale = 0);
    // The camera's primary rays (Camera::pixelRay + GridFrame::toCellRay,
    // generated on the device), traced only: one hit per pixel, row-major.
    // `lodPixels` as RenderOptions::lodPixels. The hits live in this tracer
    // until the next call: frames reuse one host array (fresh pages cost
    // about as much as the dispatch on this VM: 110 ms for 786k hits).
    const std::vector<trace::RayHit>& tracePrimary(const trace::Camera& camera, HitKind kind = HitKind::FirstHit, double lodPixels = 0);
    // Renders `grid` (the grid given at construction) like trace::renderCpu.
    trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                        trace::RenderStats& stats);
    // The walk's arithmetic (gpu/shaders/trace_walk.glsl): each step decided
    // in 32-bit floats, in doubles only where the floats are too close to
    // call (the default on GPUs, which run doubles at 1/2-1/64 the rate of
    // floats), or every step in doubles (the default on a CPU device such
    // as lavapipe, where doubles cost no more). The hits are the same either
    // way, bit for bit; RayHit::wideSteps counts the steps run in doubles.
    void setFloatWalk(bool on);
    bool floatWalk() const;
    // Device time of the last traceHits/render dispatch, in ms.
    double lastDeviceMs() const { return lastDeviceMs_; }

    const DeviceInfo& deviceInfo() const;
    const trace::OccupiedBox& occupiedBox() const { return box_; }

private:
    struct Impl;
    void upload(VulkanContext& context, const trace::RenderGrid& grid, uint32_t chunkShift);
    void setCamera(const trace::Camera& camera, double lodPixels);
    static void unpackHits(const void* words, std::span<trace::RayHit> hits);
    std::unique_ptr<DeviceBuffer> primaryHits_;
    std::vector<trace::RayHit> primaryHitsHost_;
    std::unique_ptr<DeviceBuffer> renderedPixels_;
    std::unique_ptr<VulkanContext> ownContext_;
    std::unique_ptr<Impl> impl_;
    trace::RenderGrid grid_;
    trace::OccupiedBox box_;
    double lastDeviceMs_ = 0;
};

} // namespace vdbdag::gpu
