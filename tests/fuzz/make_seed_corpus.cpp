// Writes a few valid .ssvdag files (compressed and raw, empty grid, tiles,
// mirrored bricks, a colour grid with quantised colours and ONV normals)
// into a folder, as the fuzzer's seed corpus.
#include <bit>
// mirrored bricks, predicted int32 values) into a folder, as the fuzzer's seed corpus.
#include <cstdio>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "src/attributes/RescaledFloats.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/pipeline/SeriesReference.h"
#include "tests/tools/ForgedDicom.h"
#include "tests/tools/ForgedScenes.h"

int main(int argc, char** argv) {
    if (argc < 2) return 2;  // usage: make_seed_corpus READER_DIR [SECTIONS_DIR [SCAN_HEADERS_DIR]]
    using namespace vdbdag;
    GridRecord record;
    record.name = "seed";
    record.vdbDescriptor = {1, 2, 3};
    for (int i = 0; i < 30; ++i) record.topology.bricks.push_back({4 * (i % 4), 4 * (i / 4), 8 * (i % 3), uint64_t(0x1234567) * uint64_t(i + 3)});
    record.topology.tiles.push_back({64, 0, 0, 3});
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    scene.grids.push_back(pipeline::encodeGrid(GridRecord{}));
    {   // The same geometry as a colour grid with normals: ColourErrors and Normals sections.
        GridRecord colour = record;
        colour.name = "Cd";
        colour.valueType = ValueType::Vec3S;
        colour.background.assign(12, 0);
        colour.normals.emplace();
        uint64_t entries = colour.topology.tiles.size();
        for (const Brick& b : colour.topology.bricks) entries += uint64_t(std::popcount(b.mask));
        uint32_t state = 7;
        auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1u << 24); };
        for (uint64_t i = 0; i < entries; ++i) {
            const float rgb[3] = {next(), next(), next()}, n[3] = {next() - 0.5f, next() - 0.5f, next() - 0.5f};
            auto& values = i + colour.topology.tiles.size() < entries ? colour.values.bricks : colour.values.tiles;
            auto& normals = i + colour.topology.tiles.size() < entries ? colour.normals->vectors.bricks : colour.normals->vectors.tiles;
            values.insert(values.end(), reinterpret_cast<const uint8_t*>(rgb), reinterpret_cast<const uint8_t*>(rgb) + 12);
            normals.insert(normals.end(), reinterpret_cast<const uint8_t*>(n), reinterpret_cast<const uint8_t*>(n) + 12);
        }
        pipeline::EncodeOptions options;
        options.colourBits = 4;
        options.normalBits = 12;
        scene.grids.push_back(pipeline::encodeGrid(colour, options));
    }
    // An int32 grid with smooth, distinct values: stored as a PredictedValues section.
    GridRecord ints = record;
    ints.valueType = ValueType::Int32;
    ints.background = {0, 0, 0, 0};
    uint64_t entries = 1;  // the tile
    for (const Brick& b : ints.topology.bricks) entries += uint64_t(__builtin_popcountll(b.mask));
    for (uint64_t i = 0; i < entries; ++i) {
        const int32_t v = int32_t(1000 + 7 * i + (i * 2654435761u) % 3);
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        (i + 1 < entries ? ints.values.bricks : ints.values.tiles).insert(i + 1 < entries ? ints.values.bricks.end() : ints.values.tiles.end(), p, p + 4);
    }
    scene.grids.push_back(pipeline::encodeGrid(ints));
    // The same as a rescaled scan's floats: a PredictedWindows section of a
    // float grid, its window coded as the lattice's integers (coding 5).
    GridRecord rescaled = ints;
    rescaled.name = "rescaled";
    rescaled.valueType = ValueType::Float;
    rescaled.rescale = ValueRescale{2.0222414, -3.0};
    for (auto* values : {&rescaled.values.bricks, &rescaled.values.tiles})
        for (size_t at = 0; at + 4 <= values->size(); at += 4) {
            int32_t k;
            std::memcpy(&k, values->data() + at, 4);
            const float f = attributes::rescaledFloat(k, *rescaled.rescale);
            std::memcpy(values->data() + at, &f, 4);
        }
    scene.grids.push_back(pipeline::encodeGrid(rescaled));
    // The next volume of a series: the same voxels, each integer moved by
    // at most 2; the pass below codes it against the one before
    // (ValueReference, coding 22: docs/FORMAT.md 8.6).
    GridRecord next = rescaled;
    next.name = "rescaled_t1";
    for (auto* values : {&next.values.bricks, &next.values.tiles})
        for (size_t at = 0; at + 4 <= values->size(); at += 4) {
            float f;
            std::memcpy(&f, values->data() + at, 4);
            const int64_t k = std::llround((double(f) - next.rescale->intercept) / next.rescale->slope) + int64_t(at / 4 % 5) - 2;
            f = attributes::rescaledFloat(k, *next.rescale);
            std::memcpy(values->data() + at, &f, 4);
        }
    scene.grids.push_back(pipeline::encodeGrid(next));
    // Labels: a 24x16x8 box in three regions split by planes, most entries
    // repeating the one before, its two uniform 8^3 blocks (x < 8) tiles as
    // a scan's import makes them: a PredictedWindows section whose window is
    // coded as labels with tiles as neighbours (coding 18, coding/LabelCoder.h),
    // over a DAG whose attribute offsets are at rest.
    scene.grids.push_back(pipeline::encodeGrid(vdbdag::testing::labelBox(
        "labels", 6, 4, 2, [](int x, int y, int z) { return int32_t(x < 8 ? 17 : x + y < 20 ? 4000 + z / 4 : -250); }, true)));
    // Half floats (13 zero low bits) of a turbulent field filling a 16^3
    // box: a float window stored as coding 12, the integers of the floats'
    // order (coding/FloatIntegerCoder.h), for the reader fuzzers to mutate.
    {
        GridRecord half;
        half.name = "half";
        half.valueType = ValueType::Float;
        half.background = {0, 0, 0, 0};
        uint32_t lcg = 12345;
        for (int bz = 0; bz < 16; bz += 4)
            for (int by = 0; by < 16; by += 4)
                for (int bx = 0; bx < 16; bx += 4) {
                    half.topology.bricks.push_back({bx, by, bz, ~uint64_t(0)});
                    for (int i = 0; i < 64; ++i) {  // stored order: x fastest
                        const int x = bx + (i & 3), y = by + (i >> 2 & 3), z = bz + (i >> 4);
                        lcg = lcg * 1664525u + 1013904223u;
                        const float f = 0.6f + 0.5f * std::sin(0.21f * float(x) + 0.07f * float(y)) * std::cos(0.17f * float(z)) + float(lcg >> 20) * 2e-5f;
                        uint32_t bits;
                        std::memcpy(&bits, &f, 4);
                        bits &= ~uint32_t(0x1FFF);
                        half.values.bricks.insert(half.values.bricks.end(), reinterpret_cast<const uint8_t*>(&bits), reinterpret_cast<const uint8_t*>(&bits) + 4);
                    }
                }
        scene.grids.push_back(pipeline::encodeGrid(half));
    }
    if (pipeline::referenceSeries(scene).referencedGrids != 1) std::fprintf(stderr, "make_seed_corpus: the series' second volume took no reference\n");
    int n = 0;
    for (bool compress : {true, false}) {
        format::ContainerOptions options;
        options.compress = compress;
        const auto bytes = format::writeScene(scene, options);
        std::ofstream(std::string(argv[1]) + "/seed" + std::to_string(n++) + ".ssvdag", std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    // The same grids as a sequence file: two frames, the first with file
    // metadata (format 4.3: Frames and FrameMetadata sections).
    {
        format::SsvdagScene sequence = scene;
        const uint32_t count = uint32_t(sequence.grids.size());
        sequence.frames = {{7, 0, 1, {1, 2, 3, 4}}, {9, 1, count - 1, {}}};
        const auto bytes = format::writeScene(sequence);
        std::ofstream(std::string(argv[1]) + "/sequence.ssvdag", std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    // Bare containers: no sections, and a few sections (empty, compressible,
    // incompressible, an unknown kind), zstd and raw.
    std::vector<format::Section> bare;
    bare.push_back({format::SectionKind::FileInfo, 0, {}});
    bare.push_back({format::SectionKind::DagInner, 1, std::vector<uint8_t>(1500, 0x5A)});
    std::vector<uint8_t> noise(200);
    uint32_t x = 12345;
    for (auto& b : noise) b = uint8_t((x = x * 1664525u + 1013904223u) >> 24);
    bare.push_back({format::SectionKind::DagLeaves, 1, noise});
    bare.push_back({format::SectionKind(99), 2, {1, 2, 3}});
    for (const auto& list : {std::vector<format::Section>{}, bare}) {
        for (bool compress : {true, false}) {
            format::ContainerOptions options;
            options.compress = compress;
            const auto bytes = format::writeContainer(list, options);
            std::ofstream(std::string(argv[1]) + "/container" + std::to_string(n++) + ".ssvdag", std::ios::binary)
                .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        }
    }
    // The forged files of the read-limit tests (tests/unit/test_read_limits.cpp):
    // an expansion (a solid 256^3 block of full bricks, 2^24 entries in a few
    // hundred bytes), the same with its values in one legacy Values section
    // (palettes, decoded whole), and a DAG whose voxels reach past INT32_MAX.
    {
        format::SsvdagScene forged;
        forged.grids.push_back(pipeline::encodeGrid(vdbdag::testing::solidFloatBlock("block", 256)));
        const auto expansion = format::writeScene(forged);
        std::ofstream(std::string(argv[1]) + "/forged_expansion.ssvdag", std::ios::binary)
            .write(reinterpret_cast<const char*>(expansion.data()), std::streamsize(expansion.size()));
        vdbdag::testing::useLegacyValues(forged.grids[0]);
        const auto legacy = format::writeScene(forged);
        std::ofstream(std::string(argv[1]) + "/forged_legacy_values.ssvdag", std::ios::binary)
            .write(reinterpret_cast<const char*>(legacy.data()), std::streamsize(legacy.size()));
        GridRecord far = record;
        far.name = "far";
        format::SsvdagScene farScene;
        farScene.grids.push_back(pipeline::encodeGrid(far));
        farScene.grids[0].active.dag.origin[0] = 2147483640;  // voxels past INT32_MAX
        const auto farBytes = format::writeScene(farScene);
        std::ofstream(std::string(argv[1]) + "/forged_far.ssvdag", std::ios::binary)
            .write(reinterpret_cast<const char*>(farBytes.data()), std::streamsize(farBytes.size()));
    }
    // The same scene in the checksum-free section framing of fuzz_ssvdag_sections.
    if (argc > 2) {
        const auto sections = format::sceneToSections(scene);
        std::vector<uint8_t> framed{uint8_t(sections.size())};
        for (const auto& section : sections) {
            framed.push_back(uint8_t(section.kind));
            framed.push_back(uint8_t(section.grid));
            const uint16_t length = uint16_t(section.data.size());
            framed.push_back(uint8_t(length & 0xFF));
            framed.push_back(uint8_t(length >> 8));
            framed.insert(framed.end(), section.data.begin(), section.data.begin() + length);
        }
        std::ofstream(std::string(argv[2]) + "/seed_sections", std::ios::binary)
            .write(reinterpret_cast<const char*>(framed.data()), std::streamsize(framed.size()));
    }
    // Forged DICOM files of the hostile-input tests for fuzz_scan_headers
    // (format byte 4): a 65535x65535 header over 64 bytes of pixels, and
    // the same slice with its 2x2 pixels.
    if (argc > 3) {
        for (const auto& [name, bytes] : {std::pair{"forged_huge_slice", testing::forgedCtSlice(65535, 65535, 64)},
                                          std::pair{"forged_small_slice", testing::forgedCtSlice(2, 2, 8)}})
            std::ofstream(std::string(argv[3]) + "/" + name, std::ios::binary) << '\004' << bytes;
    }
    return 0;
}
