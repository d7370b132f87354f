// Encode throughput on the d=1024 sphere level set (the equivalent of
// `vdb_tool -sphere d=1024 r=1.0 w=3`, 19.5M active voxels), with baselines
// run in the same process:
//   BM_OpenVdbReadWrite  OpenVDB alone: read the .vdb, write its topology as
//                        a blosc MaskGrid (what a user would otherwise do);
//   BM_EncodeFile        vdbdag, geometry only (`encode --topology-only`): read
//                        the .vdb, build + reduce + encode, write the .ssvdag;
//   BM_EncodeFileWithValues  the same with every value, lossless;
//   BM_ReduceOnly        the SSVDAG reduction alone (bricks -> reduced DAG);
//   BM_ReduceOnlyOneCore the same on one core (the reference code reduces
//                        17-20M voxels/s on one core of this machine);
//   BM_ReduceOnlyPlain   the plain SVDAG reduction, for the symmetry cost.
// Counters: voxels/s (items_per_second), peak RSS in MiB.
// Run: build/vdbdag_bench --benchmark_filter=Sphere
#include <benchmark/benchmark.h>

#include <filesystem>
#include <sys/resource.h>

#include <tbb/global_control.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "src/dag/DagBuilder.h"
#include "src/encoding/CompactDag.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "vdb_bridge/VdbImport.h"

namespace {

double peakRssMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

const std::string& sphereFile() {
    static const std::string path = [] {
        openvdb::initialize();
        const std::string p = (std::filesystem::temp_directory_path() / "vdbdag_bench_sphere_d1024.vdb").string();
        if (!std::filesystem::exists(p)) {
            // d=1024, r=1.0: voxel size 2/1024, half width 3 voxels (vdb_tool's -sphere).
            auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 2.0f / 1024.0f, 3.0f);
            grid->setName("sphere");
            openvdb::io::File file(p + ".tmp");
            file.write({grid});
            file.close();
            std::filesystem::rename(p + ".tmp", p);
        }
        return p;
    }();
    return path;
}

const vdbdag::Volume& sphereVolume() {
    static const vdbdag::Volume volume = vdbdag::bridge::importVdb(sphereFile()).volume;
    return volume;
}

uint64_t sphereVoxels() { return sphereVolume().grids.at(0).topology.activeVoxelCount(); }

void BM_OpenVdbReadWrite_Sphere(benchmark::State& state) {
    sphereVolume();  // generate and import once, outside the timing
    const std::string out = (std::filesystem::temp_directory_path() / "vdbdag_bench_mask.vdb").string();
    for (auto _ : state) {
        openvdb::io::File in(sphereFile());
        in.open();
        auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid("sphere"));
        in.close();
        auto mask = openvdb::MaskGrid::create();
        mask->tree().topologyUnion(grid->tree());
        mask->setTransform(grid->transform().copy());
        openvdb::io::File file(out);
        file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
        file.write({mask});
        file.close();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(sphereVoxels()));
    state.counters["peak_rss_MiB"] = peakRssMiB();
    state.counters["bytes"] = double(std::filesystem::file_size(out));
}

void encodeFile(benchmark::State& state, bool topologyOnly) {
    sphereVolume();
    const std::string out = (std::filesystem::temp_directory_path() / "vdbdag_bench_sphere.ssvdag").string();
    size_t bytes = 0;
    vdbdag::bridge::ImportOptions options;
    options.topologyOnly = topologyOnly;
    for (auto _ : state) {
        const auto imported = vdbdag::bridge::importVdb(sphereFile(), options);
        vdbdag::pipeline::EncodeOptions encodeOptions;
        encodeOptions.computeSvdagStats = false;  // as the CLI does by default
        const auto scene = vdbdag::pipeline::encodeVolume(imported.volume, encodeOptions);
        const auto data = vdbdag::format::writeScene(scene);
        vdbdag::writeFileAtomically(out, data);
        bytes = data.size();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(sphereVoxels()));
    state.counters["peak_rss_MiB"] = peakRssMiB();
    state.counters["bytes"] = double(bytes);
}
// Geometry only (`encode --topology-only`), and the full lossless encode with values.
void BM_EncodeFile_Sphere(benchmark::State& state) { encodeFile(state, true); }
void BM_EncodeFileWithValues_Sphere(benchmark::State& state) { encodeFile(state, false); }

void reduce(benchmark::State& state, bool symmetry) {
    const vdbdag::GridTopology& topo = sphereVolume().grids.at(0).topology;
    vdbdag::dag::BuildOptions options;
    options.symmetry = symmetry;
    size_t bytes = 0;
    for (auto _ : state) {
        const auto reduced = vdbdag::dag::buildDag(topo, options);
        bytes = vdbdag::encoding::encodeCompact(reduced).byteSize();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(sphereVoxels()));
    state.counters["traceable_bytes"] = double(bytes);
    state.counters["peak_rss_MiB"] = peakRssMiB();
}
void BM_ReduceOnly_Sphere(benchmark::State& state) { reduce(state, true); }
// One core, for comparison with the paper's single-threaded reference builder.
void BM_ReduceOnlyOneCore_Sphere(benchmark::State& state) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    reduce(state, true);
}
void BM_ReduceOnlyPlain_Sphere(benchmark::State& state) { reduce(state, false); }

} // namespace

BENCHMARK(BM_OpenVdbReadWrite_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_EncodeFile_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_EncodeFileWithValues_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_ReduceOnly_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_ReduceOnlyOneCore_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_ReduceOnlyPlain_Sphere)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

// BENCHMARK_MAIN lives here; the other bench_*.cpp files only register.
BENCHMARK_MAIN();
