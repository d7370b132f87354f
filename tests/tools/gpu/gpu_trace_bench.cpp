// Trace throughput of the project's Vulkan tracer (and its CPU tracer) on one
// .ssvdag, the default camera of `vdbdag render`, at three resolutions: the
// GPU measurement of issue 42, run by tests/tools/gpu/run.sh on a lent GPU
// machine beside NanoVDB's HDDA in CUDA (nvdb_trace.cu) on the very same
// rays. Built with the project (vdbdag_gpu_trace_bench), so it never goes
// stale; scripts/gpu_bundle.sh packs it for the GPU machine.
//
// One line per (resolution, hit kind, tracer): the Vulkan walk in floats
// (doubles only where floats cannot tell: the default on GPUs) and in
// doubles throughout, with the share of steps that ran in doubles, and the
// CPU tracer (TBB, every core) when asked; and each camera, so that
// nvdb_trace shoots the same rays.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gpu/VulkanContext.h"
#include "gpu/VulkanTracer.h"
#include "src/format/SsvdagFile.h"
#include "src/trace/Camera.h"
#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/SurfaceHit.h"
#include "src/util/Error.h"

using namespace vdbdag;
using Clock = std::chrono::steady_clock;

namespace {
double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}
} // namespace

int main(int argc, char** argv) try {
    if (argc < 3) {
        std::fprintf(stderr, "usage: vdbdag_gpu_trace_bench FILE.ssvdag FRAMES [cpu] [--small]\n");
        return 2;
    }
    const int frames = std::max(1, std::atoi(argv[2]));
    bool cpu = false, small = false;
    for (int i = 3; i < argc; ++i) {
        cpu |= std::string(argv[i]) == "cpu";
        small |= std::string(argv[i]) == "--small";  // 1024x768 only (a check on lavapipe)
    }
    const format::SsvdagScene scene = format::readSceneFile(argv[1]);
    const format::EncodedGrid& eg = scene.grids.at(0);
    const trace::RenderGrid grid = trace::makeRenderGrid(eg);
    const trace::GridFrame frame(grid.indexToWorld);
    auto context = std::make_unique<gpu::VulkanContext>();
    gpu::VulkanTracer tracer(*context, grid);
    std::printf("device %s (%s)\n", tracer.deviceInfo().name.c_str(), tracer.deviceInfo().type.c_str());
    const trace::DagTracer cpuTracer(eg.active.dag);
    const int sizes[3][2] = {{1024, 768}, {1920, 1080}, {3840, 2160}};
    for (int si = 0; si < (small ? 1 : 3); ++si) {
        const int w = sizes[si][0], h = sizes[si][1];
        const trace::Camera cam = trace::frameBounds(frame, grid.cellLo, grid.cellHi, w, h);
        std::printf("camera %d %d fov %.17g eye %.17g %.17g %.17g target %.17g %.17g %.17g up %.17g %.17g %.17g\n", w, h, cam.fovDegrees,
                    cam.eye.x, cam.eye.y, cam.eye.z, cam.target.x, cam.target.y, cam.target.z, cam.up.x, cam.up.y, cam.up.z);
        const double rays = double(w) * h;
        for (int k = 0; k < 2; ++k) {
            const auto kind = k == 0 ? gpu::HitKind::FirstHit : gpu::HitKind::Surface;
            const char* kname = k == 0 ? "firsthit" : "surface";
            uint64_t hits = 0;
            for (const bool floatWalk : {true, false}) {
                tracer.setFloatWalk(floatWalk);
                tracer.tracePrimary(cam, kind);  // pipeline compile and first touch outside the timing
                std::vector<double> dev, wall;
                uint64_t steps = 0, wideSteps = 0;
                for (int f = 0; f < frames; ++f) {
                    const auto t0 = Clock::now();
                    const auto& r = tracer.tracePrimary(cam, kind);
                    const auto t1 = Clock::now();
                    dev.push_back(tracer.lastDeviceMs());
                    wall.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
                    hits = steps = wideSteps = 0;
                    for (const auto& hit : r) hits += hit.hit, steps += hit.steps, wideSteps += hit.wideSteps;
                }
                std::printf("vulkan-%s %dx%d %s device_ms %.4f wall_ms %.3f Mrays_s_device %.1f Mrays_s_wall %.1f hit_fraction %.4f "
                            "steps_in_doubles %.5f\n",
                            floatWalk ? "fp32" : "fp64", w, h, kname, median(dev), median(wall), rays / median(dev) / 1e3,
                            rays / median(wall) / 1e3, double(hits) / rays, double(wideSteps) / double(std::max<uint64_t>(steps, 1)));
            }
            if (!cpu) continue;
            std::vector<double> times;
            for (int f = 0; f < 3; ++f) {
                std::atomic<uint64_t> found{0};
                const auto t0 = Clock::now();
                tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
                    uint64_t local = 0;
                    for (int y = rows.begin(); y != rows.end(); ++y)
                        for (int x = 0; x < w; ++x) {
                            glm::dvec3 eye, dir;
                            cam.pixelRay(x, y, eye, dir);
                            const trace::Ray ray = frame.toCellRay(eye, dir);
                            local += (k == 0 ? cpuTracer.trace(ray).hit : trace::firstSurfaceHit(grid, cpuTracer, ray).hit) ? 1 : 0;
                        }
                    found += local;
                });
                times.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
                hits = found;
            }
            std::printf("cpu %dx%d %s wall_ms %.3f Mrays_s %.1f hit_fraction %.4f\n", w, h, kname, median(times), rays / median(times) / 1e3,
                        double(hits) / rays);
        }
        std::fflush(stdout);
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "vdbdag_gpu_trace_bench: %s\n", e.what());
    return 1;
}
