// Point lookups per second, vdbdag::Accessor (the public reader,
// include/vdbdag/vdbdag.h) against NanoVDB's ReadAccessor on the same
// coordinates of the same grid, in one process: the bunny level set
// (a generated d=512 sphere when ../shared/data is absent), lossless.
//   BM_Lookup_Random_{Vdbdag,NanoVdb}    10^6 coordinates: half random active
//                                        voxels, half uniform in the bounding box
//   BM_Lookup_Coherent_{Vdbdag,NanoVdb}  a 128^3 box through the middle of the
//                                        surface, k fastest (a dense sample)
// Both sum the values they read, so neither lookup can be skipped; the sums
// must agree (checked once, before timing). Counter: lookups/s
// (items_per_second). Report the ratios vdbdag / NanoVDB (the goal for the
// coherent case: >= 0.5x).
// Run: build/vdbdag_bench --benchmark_filter=Lookup
#include <benchmark/benchmark.h>

#include <vdbdag/vdbdag.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <random>

#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "vdb_bridge/VdbImport.h"

namespace {

struct LookupScene {
    std::string ssvdagPath;
    std::unique_ptr<vdbdag::File> file;
    nanovdb::GridHandle<nanovdb::HostBuffer> nano;
    std::vector<std::array<int32_t, 3>> random, coherent;
};

const LookupScene& scene() {
    static const LookupScene s = [] {
        openvdb::initialize();
        LookupScene out;
        std::string path = std::string(VDBDAG_SHARED_DATA) + "/levelsets/bunny_d512_ls.vdb";
        if (!std::filesystem::exists(path)) {
            path = (std::filesystem::temp_directory_path() / "vdbdag_bench_lookup_sphere.vdb").string();
            auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 2.0f / 512.0f, 3.0f);
            openvdb::io::File(path).write({grid});
        }
        openvdb::io::File vdbFile(path);
        vdbFile.open();
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(vdbFile.getGrids()->at(0));
        vdbFile.close();
        out.nano = nanovdb::openToNanoVDB(*grid);
        // The .ssvdag, written by the same encoder as `vdbdag encode`.
        const auto imported = vdbdag::bridge::importVdb(path);
        vdbdag::format::SsvdagScene scene;
        scene.grids.push_back(vdbdag::pipeline::encodeGrid(imported.volume.grids.at(0)));
        const std::vector<uint8_t> bytes = vdbdag::format::writeScene(scene);
        out.ssvdagPath = (std::filesystem::temp_directory_path() / "vdbdag_bench_lookup.ssvdag").string();
        std::ofstream(out.ssvdagPath, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        out.file = std::make_unique<vdbdag::File>(vdbdag::File::open(out.ssvdagPath));
        std::vector<openvdb::Coord> active;
        for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf)
            for (auto v = leaf->cbeginValueOn(); v; ++v) active.push_back(v.getCoord());
        const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
        std::mt19937_64 rng(17);
        for (int i = 0; i < 1000000; ++i) {
            if (i % 2 == 0) {
                const openvdb::Coord c = active[rng() % active.size()];
                out.random.push_back({c.x(), c.y(), c.z()});
            } else {
                std::array<int32_t, 3> c;
                for (int a = 0; a < 3; ++a) c[a] = box.min()[a] + int32_t(rng() % uint64_t(box.max()[a] - box.min()[a] + 1));
                out.random.push_back(c);
            }
        }
        const openvdb::Vec3d centre = box.getCenter();
        const openvdb::Coord lo = openvdb::Coord::round(centre) - openvdb::Coord(64);
        for (int i = 0; i < 128; ++i)
            for (int j = 0; j < 128; ++j)
                for (int k = 0; k < 128; ++k) out.coherent.push_back({lo.x() + i, lo.y() + j, lo.z() + k});
        return out;
    }();
    return s;
}

double sumVdbdag(const std::vector<std::array<int32_t, 3>>& coords) {
    vdbdag::Accessor a = scene().file->grid(0).accessor();
    double sum = 0;
    for (const auto& c : coords) sum += a.value<float>(c[0], c[1], c[2]);
    return sum;
}

double sumNano(const std::vector<std::array<int32_t, 3>>& coords) {
    const auto* grid = scene().nano.grid<float>();
    auto a = grid->getAccessor();
    double sum = 0;
    for (const auto& c : coords) sum += a.getValue(nanovdb::Coord(c[0], c[1], c[2]));
    return sum;
}

template <double (*Sum)(const std::vector<std::array<int32_t, 3>>&)>
void lookups(benchmark::State& state, const std::vector<std::array<int32_t, 3>>& coords) {
    if (sumVdbdag(coords) != sumNano(coords)) {
        state.SkipWithError("vdbdag and NanoVDB read different values");
        return;
    }
    for (auto _ : state) benchmark::DoNotOptimize(Sum(coords));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(coords.size()));
}

void BM_Lookup_Random_Vdbdag(benchmark::State& state) { lookups<sumVdbdag>(state, scene().random); }
void BM_Lookup_Random_NanoVdb(benchmark::State& state) { lookups<sumNano>(state, scene().random); }
void BM_Lookup_Coherent_Vdbdag(benchmark::State& state) { lookups<sumVdbdag>(state, scene().coherent); }
void BM_Lookup_Coherent_NanoVdb(benchmark::State& state) { lookups<sumNano>(state, scene().coherent); }

// File::open of the same file: the section table, checksums, the DAG
// inflated; values left as stored until first asked for.
void BM_Lookup_FileOpen(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(vdbdag::File::open(scene().ssvdagPath).gridCount());
}

} // namespace

BENCHMARK(BM_Lookup_Random_Vdbdag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Lookup_Random_NanoVdb)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Lookup_Coherent_Vdbdag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Lookup_Coherent_NanoVdb)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Lookup_FileOpen)->Unit(benchmark::kMillisecond);
