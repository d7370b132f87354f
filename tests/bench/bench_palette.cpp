// Palette compressor throughput (Dado et al. §4.2, Alg. 1) on a 10^8-entry
// float array with spatially coherent values (a slowly varying quantised
// field with plateaus, like level-set distances in DAG order), and on unique
// floats (the direct-storage fallback). Baseline in the same process: a
// plain copy of the array (memory bandwidth). Counters: entries/s, bytes
// after compression, peak RSS, CPU seconds of all threads.
// Run: build/vdbdag_bench --benchmark_filter=Palette
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <random>
#include <sys/resource.h>

#include "src/attributes/PaletteChannel.h"
#include "src/attributes/PaletteCompressor.h"

namespace {

constexpr size_t kEntries = 100'000'000;

const std::vector<uint8_t>& coherentField() {
    static const std::vector<uint8_t> bytes = [] {
        std::vector<float> v(kEntries);
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = float(int(std::sin(double(i) * 1e-4) * 1000)) / 1000.0f + ((i / 5000) % 7 == 0 ? 0.5f : 0.0f);
        std::vector<uint8_t> b(v.size() * 4);
        std::memcpy(b.data(), v.data(), b.size());
        return b;
    }();
    return bytes;
}

double peakRssMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

// CPU seconds of the whole process (all threads): on a shared machine the
// wall time depends on the other users' load, this does not.
double processCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

void BM_CopyBaseline_Palette(benchmark::State& state) {
    const auto& input = coherentField();
    for (auto _ : state) {
        std::vector<uint8_t> copy(input);
        benchmark::DoNotOptimize(copy.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kEntries));
}

void BM_CompressCoherent_Palette(benchmark::State& state) {
    const auto& input = coherentField();
    uint64_t bytes = 0;
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) bytes = vdbdag::attributes::compressPalette(input, 4).byteSize();
    state.counters["process_cpu_s"] = (processCpuSeconds() - cpu0) / double(state.iterations());
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kEntries));
    state.counters["bytes"] = double(bytes);
    state.counters["raw_bytes"] = double(input.size());
    state.counters["peak_rss_MiB"] = peakRssMiB();
}

void BM_CompressUnique_Palette(benchmark::State& state) {
    std::vector<uint8_t> input(size_t(state.range(0)) * 4);
    std::mt19937 rng(1);
    for (size_t i = 0; i < input.size(); i += 4) { const uint32_t r = rng(); std::memcpy(&input[i], &r, 4); }
    uint64_t bytes = 0;
    for (auto _ : state) bytes = vdbdag::attributes::compressPalette(input, 4).byteSize();
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
    state.counters["bytes"] = double(bytes);
    state.counters["raw_bytes"] = double(input.size());
}

} // namespace

BENCHMARK(BM_CopyBaseline_Palette)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK(BM_CompressCoherent_Palette)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_CompressUnique_Palette)->Arg(10'000'000)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
