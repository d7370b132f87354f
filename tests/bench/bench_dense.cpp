// Dense-scan throughput at Christmas-tree scale (issue 5): the CT phantom of
// samples/make_ct_phantom.cpp, 512x512x999 uint16 (12-bit), ~262M samples,
// generated once into the temp folder (VDBDAG_BENCH_PHANTOM=PREFIX to use an
// existing PREFIX.nhdr). Baseline in the same process:
//   BM_DenseBaselineFreadCopyFromDense  fread the raw file, then OpenVDB's
//                      tools::copyFromDense into an Int32Grid (what a user
//                      would write by hand; holds the whole raw file);
//   BM_DenseImportToVolume  vdbdag's reader: NRRD header, z-slab stream,
//                      4^3 bricks (what `encode` starts with);
//   BM_DenseImportCommand   `vdbdag import`: the above + OpenVDB grid +
//                      .vdb written by OpenVDB;
//   BM_DenseEncodeCommand   `vdbdag encode`: read, build + reduce, attribute
//                      order, palettes and brick predictor, .ssvdag written.
// Counters: samples/s (items_per_second), bytes/s of raw input, peak RSS of
// the process so far (MiB; the per-command peak is measured with
// /usr/bin/time -v, see README).
// Run: build/vdbdag_bench --benchmark_filter=Dense
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/resource.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "tests/unit/BuildPaths.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/VdbExport.h"

namespace fs = std::filesystem;

namespace {

double peakRssMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

const std::string& phantomPrefix() {
    static const std::string prefix = [] {
        if (const char* env = std::getenv("VDBDAG_BENCH_PHANTOM")) return std::string(env);
        const std::string p = (fs::temp_directory_path() / "vdbdag_bench_tree_512x512x999").string();
        if (!fs::exists(p + ".nhdr") || !fs::exists(p + ".raw")) {
            const std::string command = std::string(VDBDAG_PHANTOM_TOOL) + " " + p + " > /dev/null";
            if (std::system(command.c_str()) != 0) std::fprintf(stderr, "bench: cannot generate the phantom\n");
        }
        return p;
    }();
    return prefix;
}

constexpr int kX = 512, kY = 512, kZ = 999;
constexpr int64_t kSamples = int64_t(kX) * kY * kZ;

void setCounters(benchmark::State& state) {
    state.SetItemsProcessed(int64_t(state.iterations()) * kSamples);
    state.SetBytesProcessed(int64_t(state.iterations()) * kSamples * 2);
    state.counters["peak_rss_MiB"] = peakRssMiB();
}

void BM_DenseBaselineFreadCopyFromDense(benchmark::State& state) {
    openvdb::initialize();
    const std::string raw = phantomPrefix() + ".raw";
    for (auto _ : state) {
        std::vector<uint16_t> samples(static_cast<size_t>(kSamples));
        FILE* f = std::fopen(raw.c_str(), "rb");
        if (!f || std::fread(samples.data(), 2, samples.size(), f) != samples.size()) state.SkipWithError("cannot read the phantom");
        if (f) std::fclose(f);
        const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(kX - 1, kY - 1, kZ - 1));
        openvdb::tools::Dense<uint16_t, openvdb::tools::LayoutXYZ> dense(box, samples.data());  // x fastest, as the file
        openvdb::Int32Grid::Ptr grid = openvdb::Int32Grid::create(0);
        openvdb::tools::copyFromDense(dense, *grid, 0);
        benchmark::DoNotOptimize(grid->activeVoxelCount());
    }
    setCounters(state);
}
BENCHMARK(BM_DenseBaselineFreadCopyFromDense)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

void BM_DenseImportToVolume(benchmark::State& state) {
    vdbdag::bridge::DenseImportOptions options;
    options.showProgress = false;
    for (auto _ : state) {
        const auto imported = vdbdag::bridge::importDense(phantomPrefix() + ".nhdr", options);
        benchmark::DoNotOptimize(imported.volume.grids.front().topology.bricks.size());
    }
    setCounters(state);
}
BENCHMARK(BM_DenseImportToVolume)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

void BM_DenseImportCommand(benchmark::State& state) {
    vdbdag::bridge::DenseImportOptions options;
    options.showProgress = false;
    const std::string out = (fs::temp_directory_path() / "vdbdag_bench_tree.vdb").string();
    for (auto _ : state) {
        const auto imported = vdbdag::bridge::importDense(phantomPrefix() + ".nhdr", options);
        vdbdag::bridge::exportVdb(imported.volume, out);
    }
    setCounters(state);
    state.counters["vdb_bytes"] = double(fs::file_size(out));
    fs::remove(out);
}
BENCHMARK(BM_DenseImportCommand)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

void BM_DenseEncodeCommand(benchmark::State& state) {
    vdbdag::bridge::DenseImportOptions options;
    options.showProgress = false;
    const std::string out = (fs::temp_directory_path() / "vdbdag_bench_tree.ssvdag").string();
    size_t bytes = 0;
    for (auto _ : state) {
        auto imported = vdbdag::bridge::importDense(phantomPrefix() + ".nhdr", options);
        vdbdag::pipeline::EncodeOptions encode;
        vdbdag::format::SsvdagScene scene = vdbdag::pipeline::encodeVolumeReleasing(imported.volume, encode);
        for (auto& g : scene.grids) std::vector<uint8_t>().swap(g.active.attributes);
        const std::vector<uint8_t> file = vdbdag::format::writeScene(scene);
        vdbdag::writeFileAtomically(out, file);
        bytes = file.size();
    }
    setCounters(state);
    state.counters["ssvdag_bytes"] = double(bytes);
    state.counters["ssvdag_over_raw"] = double(bytes) / double(kSamples * 2);
    fs::remove(out);
}
BENCHMARK(BM_DenseEncodeCommand)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

} // namespace
