// Primary-ray throughput at 1024x768 on the bunny level set (a generated
// sphere when ../shared/data is absent), all tracers on the same grid and
// camera, in one process:
//   BM_FirstHit_Ssvdag / _Svdag   first active voxel, SSVDAG vs plain SVDAG
//                                 (the paper: symmetry costs 1-2%);
//   BM_ZeroCrossing_Ssvdag        first voxel with value <= 0 (what a level-set
//                                 renderer needs), the CPU tracer;
//   BM_ZeroCrossing_NanoVdb       NanoVDB's HDDA ZeroCrossing on the same grid
//                                 (libnanovdb-dev): the baseline to beat;
//   BM_Vulkan_FirstHit_Ssvdag / _Svdag, BM_Vulkan_ZeroCrossing_Ssvdag
//                                 the same rays on the Vulkan tracer
//                                 (gpu/shaders/trace.comp, primary mode: the
//                                 camera rays generated on the device, one
//                                 hit per pixel read back), skipped without a
//                                 device. On lavapipe (Vulkan on these same
//                                 CPU cores) the target is >= 0.25x the CPU
//                                 tracer's /0 figure.
// Each CPU benchmark runs on all cores (/0) and on one thread (/1).
// Counters: rays/s (items_per_second) and the fraction of rays that hit.
// Run: build/vdbdag_bench --benchmark_filter=Trace
#include <benchmark/benchmark.h>

#include <algorithm>

#include <atomic>
#include <filesystem>
#include <optional>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <nanovdb/util/HDDA.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <nanovdb/util/Ray.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "gpu/VulkanContext.h"
#include "gpu/VulkanTracer.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/Camera.h"
#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/SurfaceHit.h"
#include "src/util/Error.h"
#include "vdb_bridge/VdbImport.h"

namespace {

constexpr int kWidth = 1024, kHeight = 768;

struct TraceScene {
    std::string path;
    openvdb::FloatGrid::Ptr grid;
    vdbdag::format::EncodedGrid ssvdag, svdag;
    vdbdag::trace::Camera camera;
    std::vector<vdbdag::trace::Ray> cellRays;
    std::vector<std::array<double, 6>> worldRays;
};

const TraceScene& scene() {
    static const TraceScene s = [] {
        openvdb::initialize();
        TraceScene out;
        out.path = std::string(VDBDAG_SHARED_DATA) + "/levelsets/bunny_d512_ls.vdb";
        if (!std::filesystem::exists(out.path)) {
            out.path = (std::filesystem::temp_directory_path() / "vdbdag_bench_sphere_d512.vdb").string();
            auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 2.0f / 512.0f, 3.0f);
            openvdb::io::File file(out.path);
            file.write({grid});
            file.close();
        }
        openvdb::io::File file(out.path);
        file.open();
        out.grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.getGrids()->at(0));
        file.close();
        const auto imported = vdbdag::bridge::importVdb(out.path);
        vdbdag::pipeline::EncodeOptions options;
        out.ssvdag = vdbdag::pipeline::encodeGrid(imported.volume.grids.at(0), options);
        options.symmetry = false;
        out.svdag = vdbdag::pipeline::encodeGrid(imported.volume.grids.at(0), options);
        const vdbdag::trace::RenderGrid grid = vdbdag::trace::makeRenderGrid(out.ssvdag);
        const vdbdag::trace::GridFrame frame(grid.indexToWorld);
        out.camera = vdbdag::trace::frameBounds(frame, grid.cellLo, grid.cellHi, kWidth, kHeight);
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                glm::dvec3 eye, dir;
                out.camera.pixelRay(x, y, eye, dir);
                out.cellRays.push_back(frame.toCellRay(eye, dir));
                out.worldRays.push_back({eye.x, eye.y, eye.z, dir.x, dir.y, dir.z});
            }
        return out;
    }();
    return s;
}

template <class TraceOne>
void traceAll(benchmark::State& state, TraceOne&& traceOne) {
    const TraceScene& s = scene();
    const size_t n = s.cellRays.size();
    std::atomic<uint64_t> hits{0};
    // Arg 0: all cores; Arg 1: one thread (CPU time then measures the work
    // alone, even on a busy machine).
    std::optional<tbb::global_control> oneThread;
    if (state.range(0) == 1) oneThread.emplace(tbb::global_control::max_allowed_parallelism, 1);
    for (auto _ : state) {
        hits = 0;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            uint64_t local = 0;
            for (size_t i = r.begin(); i != r.end(); ++i) local += traceOne(i) ? 1 : 0;
            hits += local;
        });
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
    state.counters["hit_fraction"] = double(hits) / double(n);
}

void BM_Trace_FirstHit_Ssvdag(benchmark::State& state) {
    const vdbdag::trace::DagTracer tracer(scene().ssvdag.active.dag);
    traceAll(state, [&](size_t i) { return tracer.trace(scene().cellRays[i]).hit; });
}
void BM_Trace_FirstHit_Svdag(benchmark::State& state) {
    const vdbdag::trace::DagTracer tracer(scene().svdag.active.dag);
    traceAll(state, [&](size_t i) { return tracer.trace(scene().cellRays[i]).hit; });
}
void BM_Trace_ZeroCrossing_Ssvdag(benchmark::State& state) {
    const vdbdag::trace::DagTracer tracer(scene().ssvdag.active.dag);
    const vdbdag::trace::RenderGrid grid = vdbdag::trace::makeRenderGrid(scene().ssvdag);
    traceAll(state, [&](size_t i) { return vdbdag::trace::firstSurfaceHit(grid, tracer, scene().cellRays[i]).hit; });
}
void BM_Trace_ZeroCrossing_NanoVdb(benchmark::State& state) {
    static const auto handle = nanovdb::openToNanoVDB(*scene().grid);
    const nanovdb::FloatGrid* grid = handle.grid<float>();
    traceAll(state, [&](size_t i) {
        const auto& w = scene().worldRays[i];
        const nanovdb::Vec3f eye{float(w[0]), float(w[1]), float(w[2])}, dir{float(w[3]), float(w[4]), float(w[5])};
        nanovdb::Ray<float> world(eye, dir);
        nanovdb::Ray<float> index = world.worldToIndexF(*grid);
        auto acc = grid->getAccessor();
        nanovdb::Coord ijk;
        float v = 0, t = 0;
        return nanovdb::ZeroCrossing(index, acc, ijk, v, t);
    });
}

// The Vulkan tracer on the same camera: the rays are generated on the device
// exactly as Camera::pixelRay does (tests/unit/test_vulkan_tracer.cpp checks
// the hits are the CPU's), so no ray upload is timed; the hits are read back.
// The argument is the walk's arithmetic: 32 (floats, doubles only where they
// cannot tell; the default) or 64 (doubles throughout). The same hits.
void vulkanPrimary(benchmark::State& state, const vdbdag::format::EncodedGrid& encoded, vdbdag::gpu::HitKind kind) {
    std::unique_ptr<vdbdag::gpu::VulkanContext> context;
    try {
        context = std::make_unique<vdbdag::gpu::VulkanContext>();
    } catch (const vdbdag::Error& e) {
        state.SkipWithError(e.what());
        return;
    }
    const vdbdag::trace::RenderGrid grid = vdbdag::trace::makeRenderGrid(encoded);
    vdbdag::gpu::VulkanTracer tracer(*context, grid);
    tracer.setFloatWalk(state.range(0) == 32);
    tracer.tracePrimary(scene().camera, kind);  // compiles the pipeline outside the timing
    uint64_t hits = 0, steps = 0, wideSteps = 0;
    double deviceMs = 0;
    for (auto _ : state) {
        const std::vector<vdbdag::trace::RayHit>& result = tracer.tracePrimary(scene().camera, kind);
        deviceMs += tracer.lastDeviceMs();
        hits = steps = wideSteps = 0;
        for (const auto& h : result) hits += h.hit, steps += h.steps, wideSteps += h.wideSteps;
    }
    const size_t n = size_t(kWidth) * kHeight;
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
    state.counters["hit_fraction"] = double(hits) / double(n);
    state.counters["device_ms"] = deviceMs / double(state.iterations());
    state.counters["steps_in_doubles"] = double(wideSteps) / double(std::max<uint64_t>(steps, 1));  // of the hits' steps (each ray's count saturates at 127)
    state.SetLabel(tracer.deviceInfo().name);
}

void BM_Trace_Vulkan_FirstHit_Ssvdag(benchmark::State& state) { vulkanPrimary(state, scene().ssvdag, vdbdag::gpu::HitKind::FirstHit); }
void BM_Trace_Vulkan_FirstHit_Svdag(benchmark::State& state) { vulkanPrimary(state, scene().svdag, vdbdag::gpu::HitKind::FirstHit); }
void BM_Trace_Vulkan_ZeroCrossing_Ssvdag(benchmark::State& state) { vulkanPrimary(state, scene().ssvdag, vdbdag::gpu::HitKind::Surface); }

} // namespace

BENCHMARK(BM_Trace_Vulkan_FirstHit_Ssvdag)->Unit(benchmark::kMillisecond)->Arg(32)->Arg(64)->UseRealTime();
BENCHMARK(BM_Trace_Vulkan_FirstHit_Svdag)->Unit(benchmark::kMillisecond)->Arg(32)->UseRealTime();
BENCHMARK(BM_Trace_Vulkan_ZeroCrossing_Ssvdag)->Unit(benchmark::kMillisecond)->Arg(32)->Arg(64)->UseRealTime();
BENCHMARK(BM_Trace_FirstHit_Ssvdag)->Unit(benchmark::kMillisecond)->Arg(0)->Arg(1)->UseRealTime();
BENCHMARK(BM_Trace_FirstHit_Svdag)->Unit(benchmark::kMillisecond)->Arg(0)->Arg(1)->UseRealTime();
BENCHMARK(BM_Trace_ZeroCrossing_Ssvdag)->Unit(benchmark::kMillisecond)->Arg(0)->Arg(1)->UseRealTime();
BENCHMARK(BM_Trace_ZeroCrossing_NanoVdb)->Unit(benchmark::kMillisecond)->Arg(0)->Arg(1)->UseRealTime();
