// Colour quantisation (--colour-bits, ColourQuantizer.h) on 10^6 vec3s
// entries with 10^6 distinct random colours (the worst case: nothing to
// share), K = 10, 12, 14. Baseline in the same process: converting every
// entry to CIELAB once (the least any CIELAB clustering must do).
// Run: build/vdbdag_bench --benchmark_filter=Colour
#include <benchmark/benchmark.h>

#include <cstring>
#include <random>

#include "src/attributes/CieLab.h"
#include "src/attributes/ColourQuantizer.h"

namespace {

constexpr size_t kEntries = 1'000'000;

const std::vector<uint8_t>& randomColours() {
    static const std::vector<uint8_t> bytes = [] {
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::vector<float> v(kEntries * 3);
        for (float& x : v) x = u(rng);
        std::vector<uint8_t> b(v.size() * 4);
        std::memcpy(b.data(), v.data(), b.size());
        return b;
    }();
    return bytes;
}

void BM_LabConversionBaseline_Colour(benchmark::State& state) {
    const auto& input = randomColours();
    for (auto _ : state) {
        double sum = 0;
        for (size_t i = 0; i < kEntries; ++i) sum += vdbdag::attributes::srgbToLab(vdbdag::attributes::colourOf(&input[i * 12], vdbdag::ValueType::Vec3S))[0];
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kEntries));
}

void BM_Quantise_Colour(benchmark::State& state) {
    const auto& input = randomColours();
    vdbdag::attributes::ColourReport report;
    for (auto _ : state) {
        state.PauseTiming();
        std::vector<uint8_t> values(input);
        state.ResumeTiming();
        report = vdbdag::attributes::quantiseColours(values, vdbdag::ValueType::Vec3S, unsigned(state.range(0)), "bench");
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kEntries));
    state.counters["colours"] = double(report.distinctAfter);
    state.counters["mean_dE94"] = report.meanDeltaE94;
    state.counters["max_dE94"] = report.maxDeltaE94;
}

} // namespace

BENCHMARK(BM_LabConversionBaseline_Colour)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_Quantise_Colour)->Arg(10)->Arg(12)->Arg(14)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
