// What the Vulkan backend costs on this machine's device (lavapipe): 4M
// gathers of a 64-bit and a 16-bit word from a 256 MiB DeviceArray, random
// and coherent, against the same gathers in C++ on both cores (TBB) measured
// in the same process; plus the fixed cost of a 16M-item dispatch whose
// invocations return at once (workgroups of 64 and 256). Vulkan times are the dispatch's timestamp
// queries (manual time). Counter vs_cpu = C++ time / Vulkan time.
// Run: build/vdbdag_bench --benchmark_filter=Vulkan
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstring>
#include <memory>
#include <random>

#include <tbb/parallel_for.h>

#include "gpu/ComputePipeline.h"
#include "gpu/DeviceArray.h"
#include "gpu/DeviceBuffer.h"
#include "gpu/EmbeddedShaders.h"
#include "gpu/VulkanContext.h"
#include "src/util/Error.h"

namespace {

using namespace vdbdag::gpu;

constexpr size_t kBytes = 256ull << 20;
constexpr size_t kItems = 4u << 20;

struct GatherPush {
    DeviceArrayRef source;
    uint64_t indices, out64, out16;
    uint32_t itemCount, pad;
};

struct Fixture {
    std::vector<uint8_t> bytes;
    std::vector<uint64_t> randomIdx, coherentIdx;  // {index64, index16} per item
    std::unique_ptr<VulkanContext> ctx;
    std::unique_ptr<DeviceArray> array;
    std::string error;
};

Fixture& fixture() {
    static Fixture f = [] {
        Fixture x;
        x.bytes.resize(kBytes);
        std::mt19937_64 rng(1);
        for (size_t i = 0; i < kBytes; i += 8) { const uint64_t v = rng(); std::memcpy(&x.bytes[i], &v, 8); }
        for (size_t i = 0; i < kItems; ++i) {
            x.randomIdx.push_back(rng() % (kBytes / 8));
            x.randomIdx.push_back(rng() % (kBytes / 2));
            x.coherentIdx.push_back(i * 7);
            x.coherentIdx.push_back(i * 29 + 3);
        }
        try {
            x.ctx = std::make_unique<VulkanContext>();
            x.array = std::make_unique<DeviceArray>(*x.ctx, x.bytes, "bench array");
        } catch (const vdbdag::Error& e) {
            x.error = e.what();
        }
        return x;
    }();
    return f;
}

double cpuGatherMs(const std::vector<uint64_t>& idx, std::vector<uint64_t>& out64, std::vector<uint32_t>& out16) {
    const auto& bytes = fixture().bytes;
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kItems, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            uint64_t v;
            uint16_t w;
            std::memcpy(&v, &bytes[idx[2 * i] * 8], 8);
            std::memcpy(&w, &bytes[idx[2 * i + 1] * 2], 2);
            out64[i] = v;
            out16[i] = w;
        }
    });
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void BM_CpuGather_Vulkan(benchmark::State& state) {
    const auto& idx = state.range(0) ? fixture().coherentIdx : fixture().randomIdx;
    std::vector<uint64_t> out64(kItems);
    std::vector<uint32_t> out16(kItems);
    for (auto _ : state) state.SetIterationTime(cpuGatherMs(idx, out64, out16) * 1e-3);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kItems));
    state.SetLabel(state.range(0) ? "coherent" : "random");
}

void BM_VulkanGather_Vulkan(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.ctx) { state.SkipWithError(f.error.c_str()); return; }
    const auto& idx = state.range(0) ? f.coherentIdx : f.randomIdx;
    DeviceBuffer indices(*f.ctx, idx.size() * 8, MemoryKind::DeviceLocal, "indices");
    indices.upload({reinterpret_cast<const uint8_t*>(idx.data()), idx.size() * 8});
    DeviceBuffer out64(*f.ctx, kItems * 8, MemoryKind::HostVisible, "out64");
    DeviceBuffer out16(*f.ctx, kItems * 4, MemoryKind::HostVisible, "out16");
    ComputePipeline pipeline(*f.ctx, embeddedShader("selftest_gather"), {}, sizeof(GatherPush), 64, "selftest_gather");
    const GatherPush push{f.array->ref(), indices.address(), out64.address(), out16.address(), uint32_t(kItems), 0};
    std::vector<uint64_t> c64(kItems);
    std::vector<uint32_t> c16(kItems);
    double cpuMs = 1e30, gpuMs = 1e30, hostMs = 1e30;
    for (int k = 0; k < 3; ++k) cpuMs = std::min(cpuMs, cpuGatherMs(idx, c64, c16));
    for (auto _ : state) {
        const DispatchTiming t = pipeline.dispatch(kItems, push);
        state.SetIterationTime(t.deviceMs * 1e-3);
        gpuMs = std::min(gpuMs, t.deviceMs);
        hostMs = std::min(hostMs, t.hostMs);
    }
    if (std::memcmp(out64.mappedData(), c64.data(), kItems * 8) != 0) state.SkipWithError("Vulkan gather differs from C++");
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kItems));
    state.counters["cpu_ms"] = cpuMs;
    state.counters["host_ms"] = hostMs;
    state.counters["vs_cpu"] = cpuMs / gpuMs;
    state.SetLabel(state.range(0) ? "coherent" : "random");
}

void BM_VulkanEmptyDispatch_Vulkan(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.ctx) { state.SkipWithError(f.error.c_str()); return; }
    ComputePipeline pipeline(*f.ctx, embeddedShader("selftest_gather"), {}, sizeof(GatherPush), uint32_t(state.range(1)), "selftest_gather");
    const GatherPush push{f.array->ref(), 0, 0, 0, 0, 0};  // itemCount 0: every invocation returns at once
    const uint64_t n = uint64_t(state.range(0));
    for (auto _ : state) state.SetIterationTime(pipeline.dispatch(n, push).deviceMs * 1e-3);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}

} // namespace

BENCHMARK(BM_CpuGather_Vulkan)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5)->UseManualTime();
BENCHMARK(BM_VulkanGather_Vulkan)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5)->UseManualTime();
BENCHMARK(BM_VulkanEmptyDispatch_Vulkan)->ArgNames({"items", "workgroup"})->Args({1 << 24, 64})->Args({1 << 24, 256})->Unit(benchmark::kMillisecond)->Iterations(5)->UseManualTime();
