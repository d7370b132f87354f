// The public reader (include/vdbdag/vdbdag.h) against the grids that made
// the file: every lookup of vdbdag::Accessor is compared with a brute-force
// answer from the synthetic grid's own voxel and tile lists (a map lookup,
// then a scan of the tiles), which shares no code with the DAG, its
// attribute order or the value channels. Lookups are made at every stored
// voxel, at random points in and around the grid, and in a coherent scan
// (the accessor's cached path), on mirrored (SSVDAG) and plain DAGs, with
// active tiles, an inactive layer, and every channel coding (palette
// windows, predicted integer windows, vectors, bool, mask).
#include <gtest/gtest.h>

#include <vdbdag/vdbdag.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include <unistd.h>

#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/selftest/SyntheticGrid.h"

using namespace vdbdag;

namespace {

// The answer a reader must give, from the synthetic grids alone.
struct Reference {
    unsigned vs = 0;
    std::map<std::array<int64_t, 3>, std::string> active, inactive;
    std::vector<std::pair<Tile, std::string>> activeTiles, inactiveTiles;
    std::string background;

    static void add(const selftest::SyntheticGrid& g, unsigned vs, std::map<std::array<int64_t, 3>, std::string>& voxels,
                    std::vector<std::pair<Tile, std::string>>& tiles) {
        for (size_t i = 0; i < g.voxels.size(); ++i)
            voxels[{g.voxels[i][0], g.voxels[i][1], g.voxels[i][2]}] = std::string(reinterpret_cast<const char*>(g.voxelValues.data()) + i * vs, vs);
        for (size_t i = 0; i < g.tiles.size(); ++i)
            tiles.push_back({g.tiles[i], std::string(reinterpret_cast<const char*>(g.tileValues.data()) + i * vs, vs)});
    }
    static const std::string* in(const std::map<std::array<int64_t, 3>, std::string>& voxels, const std::vector<std::pair<Tile, std::string>>& tiles,
                                 int64_t x, int64_t y, int64_t z) {
        if (auto it = voxels.find({x, y, z}); it != voxels.end()) return &it->second;
        for (const auto& [t, v] : tiles) {
            const int64_t n = int64_t(1) << t.log2Size;
            if (x >= t.x && x < t.x + n && y >= t.y && y < t.y + n && z >= t.z && z < t.z + n) return &v;
        }
        return nullptr;
    }
    bool isActive(int64_t x, int64_t y, int64_t z) const { return in(active, activeTiles, x, y, z) != nullptr; }
    std::string value(int64_t x, int64_t y, int64_t z) const {
        if (const std::string* v = in(active, activeTiles, x, y, z)) return *v;
        if (const std::string* v = in(inactive, inactiveTiles, x, y, z)) return *v;
        return background;
    }
};

std::string lookup(Accessor& a, int64_t x, int64_t y, int64_t z) {
    std::string out(a.valueSize(), '\0');
    a.valueBytes(x, y, z, out.data());
    return out;
}

struct Case {
    std::string name;
    selftest::SyntheticGrid active, inactive;
};

// A shell of radius 26 (values from `value(d)`), tiles of 8^3 and 32^3, and
// an inactive inside with a tile.
template <typename MakeValue>
Case shell(ValueType type, const std::string& name, std::mt19937& rng, MakeValue&& value) {
    Case c;
    c.name = name;
    c.active.type = c.inactive.type = type;
    const unsigned vs = valueSize(type);
    std::vector<uint8_t> v(std::max(1u, vs));
    for (int z = -30; z <= 30; ++z)
        for (int y = -30; y <= 30; ++y)
            for (int x = -30; x <= 30; ++x) {
                const double d = std::sqrt((x + 0.5) * (x + 0.5) + (y + 0.5) * (y + 0.5) + (z + 0.5) * (z + 0.5)) - 26.0;
                value(d, rng, v.data());
                if (std::abs(d) < 1.5) c.active.addVoxel(x, y, z, v.data());
                else if (d < 0 && (x + 2 * y + z) % 3 != 0) c.inactive.addVoxel(x, y, z, v.data());
            }
    value(100.0, rng, v.data());
    for (int i = 0; i < 3; ++i) c.active.addTile({64 + 8 * i, 0, 0, 3}, v.data());
    c.active.addTile({128, 128, 0, 5}, v.data());
    value(-100.0, rng, v.data());
    c.inactive.addTile({-96, -96, -96, 5}, v.data());
    return c;
}

// A shell of each value type (named by its type), values from `rng`.
std::vector<Case> everyType(std::mt19937& rng) {
    std::vector<Case> cases;
    cases.push_back(shell(ValueType::Float, "float", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const float v = (r() % 4 == 0) ? float(r() % 7) : float(d);
        std::memcpy(out, &v, 4);
    }));
    cases.push_back(shell(ValueType::Int32, "int32", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const int32_t v = int32_t(std::floor(d * 3)) + int32_t(r() % 2);
        std::memcpy(out, &v, 4);
    }));
    cases.push_back(shell(ValueType::Vec3S, "vec3s", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const float v[3] = {float(d), float(r() % 5), -0.0f};
        std::memcpy(out, v, 12);
    }));
    cases.push_back(shell(ValueType::Double, "double", rng, [](double d, std::mt19937&, uint8_t* out) { std::memcpy(out, &d, 8); }));
    cases.push_back(shell(ValueType::Bool, "bool", rng, [](double d, std::mt19937&, uint8_t* out) { out[0] = d > 0.25 ? 1 : 0; }));
    cases.push_back(shell(ValueType::Mask, "mask", rng, [](double, std::mt19937&, uint8_t*) {}));
    return cases;
}

// `summaries` false: the grids without their Summary sections, as a file
// written before them (read whole on open).
std::filesystem::path writeFile(const std::vector<std::pair<Case*, bool>>& grids, const pipeline::EncodeOptions& options, const std::string& stem,
                                bool summaries = true) {
    format::SsvdagScene scene;
    for (const auto& [c, withInactive] : grids) {
        GridRecord record = selftest::toRecord(c->active, c->name);
        if (withInactive && valueSize(c->active.type)) {
            const GridRecord in = selftest::toRecord(c->inactive, c->name);
            record.inactiveTopology = in.topology;
            record.inactiveValues = in.values;
        }
        record.indexToWorld = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 1.25, -2, 3, 1};
        scene.grids.push_back(pipeline::encodeGrid(record, options));
        if (!summaries) scene.grids.back().summary.reset();
    }
    const auto path = std::filesystem::temp_directory_path() / (stem + "_" + std::to_string(::getpid()) + ".ssvdag");
    const std::vector<uint8_t> bytes = format::writeScene(scene);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return path;
}

void expectSameAnswers(const Grid& grid, const Case& c, bool withInactive, std::mt19937& rng) {
    Reference ref;
    ref.vs = valueSize(c.active.type);
    Reference::add(c.active, ref.vs, ref.active, ref.activeTiles);
    if (withInactive && ref.vs) Reference::add(c.inactive, ref.vs, ref.inactive, ref.inactiveTiles);
    ref.background.assign(ref.vs, '\0');
    Accessor a = grid.accessor();
    uint64_t checked = 0, failures = 0;
    auto check = [&](int64_t x, int64_t y, int64_t z) {
        ++checked;
        const bool on = a.isActive(x, y, z);
        const std::string v = lookup(a, x, y, z);
        if (on != ref.isActive(x, y, z) || v != ref.value(x, y, z)) {
            if (++failures <= 5)
                ADD_FAILURE() << c.name << ": voxel (" << x << "," << y << "," << z << ") active " << on << " value " << selftest::hexValue(v)
                              << ", expected active " << ref.isActive(x, y, z) << " value " << selftest::hexValue(ref.value(x, y, z));
        }
    };
    for (const auto& [p, v] : ref.active) check(p[0], p[1], p[2]);
    for (const auto& [p, v] : ref.inactive) check(p[0], p[1], p[2]);
    for (const auto& [t, v] : ref.activeTiles) check(t.x + 3, t.y + 1, t.z + 2);
    std::uniform_int_distribution<int64_t> around(-140, 200);
    for (int i = 0; i < 20000; ++i) check(around(rng), around(rng), around(rng));
    for (int64_t z = -4; z <= 4; ++z)  // coherent: a slab through the shell, x fastest
        for (int64_t y = -32; y <= 32; ++y)
            for (int64_t x = -32; x <= 32; ++x) check(x, y, z);
    for (int64_t far : {int64_t(1) << 40, -(int64_t(1) << 40), int64_t(INT32_MAX), int64_t(INT32_MIN)}) check(far, 0, 0);
    EXPECT_EQ(failures, 0u) << c.name << ": " << failures << " of " << checked << " lookups differ";
}

} // namespace

TEST(Reader, AccessorAnswersAsTheGridsThatMadeTheFile) {
    std::mt19937 rng(11);
    std::vector<Case> cases = everyType(rng);
    for (const bool symmetry : {true, false}) {
        pipeline::EncodeOptions options;
        options.symmetry = symmetry;
        std::vector<std::pair<Case*, bool>> grids;
        for (Case& c : cases) grids.push_back({&c, c.name != "bool"});  // one grid without an inactive layer
        const auto path = writeFile(grids, options, symmetry ? "reader_ssvdag" : "reader_svdag");
        const File file = File::open(path.string());
        ASSERT_EQ(file.gridCount(), cases.size());
        for (size_t g = 0; g < cases.size(); ++g) {
            const Grid& grid = file.grid(g);
            EXPECT_EQ(grid.name(), cases[g].name);
            EXPECT_EQ(grid.valueType(), cases[g].name);  // the cases are named by their type
            EXPECT_EQ(&file.grid(cases[g].name), &grid);
            expectSameAnswers(grid, cases[g], grids[g].second, rng);
        }
        std::filesystem::remove(path);
    }
}

// Opening reads the headers; a grid's DAG and values are read when it is
// first walked: with the second grid's DAG and values corrupted, the file
// opens, both grids' facts are the brute-force ones, the first grid answers
// every lookup as its case, and the second refuses its first walk with one
// error naming the file (each time it is asked). A file without Summary
// sections is read whole on open and answers the same.
TEST(Reader, AGridIsReadWhenFirstWalked) {
    std::mt19937 rng(12);
    std::vector<Case> cases = everyType(rng);
    ASSERT_GE(cases.size(), 2u);
    std::vector<std::pair<Case*, bool>> grids{{&cases[0], true}, {&cases[1], true}};
    const auto good = writeFile(grids, {}, "reader_lazy_good");
    std::vector<uint8_t> bytes = format::readFileBytes(good.string());
    for (const format::Section& s : format::storedSectionsOf(good.string()))
        if (s.grid == 1 && s.kind != format::SectionKind::GridInfo && s.kind != format::SectionKind::DagLevels && s.kind != format::SectionKind::Summary &&
            s.kind != format::SectionKind::VdbDescriptor && s.kind != format::SectionKind::DagStats && s.kind != format::SectionKind::InactiveLevels &&
            s.stored->storedBytes > 0)
            bytes[size_t(s.stored->offset + s.stored->storedBytes / 2)] ^= 0x24;
    const auto bad = std::filesystem::temp_directory_path() / ("reader_lazy_bad_" + std::to_string(::getpid()) + ".ssvdag");
    std::ofstream(bad, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const File file = File::open(bad.string());
    ASSERT_EQ(file.gridCount(), 2u);
    for (size_t g = 0; g < 2; ++g) {
        EXPECT_EQ(file.grid(g).name(), cases[g].name);
        EXPECT_EQ(file.grid(g).activeVoxelCount(), cases[g].active.voxels.size() + [&] {
            uint64_t n = 0;
            for (const Tile& t : cases[g].active.tiles) n += uint64_t(1) << (3 * t.log2Size);
            return n;
        }());
    }
    expectSameAnswers(file.grid(0), cases[0], true, rng);
    for (int attempt = 0; attempt < 2; ++attempt) {
        try {
            (void)file.grid(1).accessor();
            ADD_FAILURE() << "the corrupted grid was walked";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()).rfind(bad.string(), 0), 0u) << e.what();
        }
    }
    const auto whole = writeFile(grids, {}, "reader_lazy_whole", /*summaries=*/false);
    const File old = File::open(whole.string());
    for (size_t g = 0; g < 2; ++g) expectSameAnswers(old.grid(g), cases[g], true, rng);
    for (const auto& p : {good, bad, whole}) std::filesystem::remove(p);
}

namespace {
// value<T> of the case's own type, as the value's bytes (a mask: the
// active state, as value<bool> reads it).
std::string typedLookup(Accessor& a, ValueType type, int64_t x, int64_t y, int64_t z) {
    const auto bytes = [](const auto& v) { return std::string(reinterpret_cast<const char*>(&v), sizeof(v)); };
    switch (type) {
    case ValueType::Float: return bytes(a.value<float>(x, y, z));
    case ValueType::Double: return bytes(a.value<double>(x, y, z));
    case ValueType::Int32: return bytes(a.value<int32_t>(x, y, z));
    case ValueType::Vec3S: return bytes(a.value<std::array<float, 3>>(x, y, z));
    case ValueType::Bool: return std::string(1, a.value<bool>(x, y, z) ? '\1' : '\0');
    case ValueType::Mask: return a.value<bool>(x, y, z) ? "on" : "off";
    default: return "?";
    }
}
} // namespace

// The accessor's brick cache (a brick is copied whole when a lookup misses
// in the brick of the last miss or next to it): sweeps of a box that is not
// on the 4-voxel grid, crosses the origin and holds active and inactive
// voxels, tiles and background, in each axis order and twice (the second
// time from the cache), through value<T>, with scattered lookups between
// the sweeps; every answer is the brute-force one from the synthetic grids.
TEST(Reader, SweepsInEveryOrderAnswerFromTheBrickCacheAsTheGrids) {
    std::mt19937 rng(23);
    std::vector<Case> cases = everyType(rng);
    std::vector<std::pair<Case*, bool>> grids;
    for (Case& c : cases) grids.push_back({&c, true});
    const auto path = writeFile(grids, {}, "reader_cache");
    const File file = File::open(path.string());
    for (const Case& c : cases) {
        Reference ref;
        ref.vs = valueSize(c.active.type);
        Reference::add(c.active, ref.vs, ref.active, ref.activeTiles);
        if (ref.vs) Reference::add(c.inactive, ref.vs, ref.inactive, ref.inactiveTiles);
        ref.background.assign(ref.vs, '\0');
        const auto want = [&](int64_t x, int64_t y, int64_t z) {
            if (c.active.type == ValueType::Mask) return std::string(ref.isActive(x, y, z) ? "on" : "off");
            if (c.active.type == ValueType::Bool) return std::string(1, ref.value(x, y, z)[0] ? '\1' : '\0');
            return ref.value(x, y, z);
        };
        Accessor a = file.grid(c.name).accessor();
        uint64_t checked = 0, failures = 0;
        const auto check = [&](int64_t x, int64_t y, int64_t z) {
            ++checked;
            const std::string got = typedLookup(a, c.active.type, x, y, z);
            const bool on = a.isActive(x, y, z);
            if ((got != want(x, y, z) || on != ref.isActive(x, y, z)) && ++failures <= 5)
                ADD_FAILURE() << c.name << ": voxel (" << x << "," << y << "," << z << ") " << selftest::hexValue(got) << " active " << on << ", expected "
                              << selftest::hexValue(want(x, y, z)) << " active " << ref.isActive(x, y, z);
        };
        const int64_t lo[3] = {-31, -29, 1}, hi[3] = {6, 30, 35};  // through the shell's wall and its inactive inside
        for (int outer = 0; outer < 3; ++outer)
            for (int pass = 0; pass < 2; ++pass) {
                const int inner = (outer + 2) % 3, middle = (outer + 1) % 3;
                int64_t p[3];
                for (p[outer] = lo[outer]; p[outer] <= hi[outer]; ++p[outer])
                    for (p[middle] = lo[middle]; p[middle] <= hi[middle]; ++p[middle])
                        for (p[inner] = lo[inner]; p[inner] <= hi[inner]; ++p[inner]) check(p[0], p[1], p[2]);
                std::uniform_int_distribution<int64_t> around(-140, 200);
                for (int i = 0; i < 2000; ++i) check(around(rng), around(rng), around(rng));
            }
        for (int64_t x = 120; x < 200; ++x) check(x, 130, 3);  // across an active tile's edge
        for (int64_t x = -100; x < -60; ++x) check(x, -90, -70);  // an inactive tile
        EXPECT_EQ(failures, 0u) << c.name << ": " << failures << " of " << checked << " lookups differ";
    }
    std::filesystem::remove(path);
}

// A value that cannot be decoded is an Error from value<T> (thrown past
// the lookup's inline part, which does not throw), every time it is asked
// for; the voxels whose values do decode, the active states and the
// background still answer.
TEST(Reader, AValueThatCannotBeDecodedIsAnErrorEachTimeItIsAsked) {
    std::mt19937 rng(29);
    Case c = shell(ValueType::Float, "density", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const float v = float(d) + float(r() % 1000) * 1e-3f;
        std::memcpy(out, &v, 4);
    });
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(selftest::toRecord(c.active, c.name)));
    std::vector<uint8_t>& windows = scene.grids[0].active.valueWindows.bytes;
    ASSERT_GT(windows.size(), 64u);
    for (size_t i = 28; i < 36; ++i) windows[i] = 0;  // the first window's first bytes (after the 28-byte head, PredictedWindows.h): no zstd frame
    const auto path = std::filesystem::temp_directory_path() / ("reader_cut_" + std::to_string(::getpid()) + ".ssvdag");
    const std::vector<uint8_t> bytes = format::writeScene(scene);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const File file = File::open(path.string());
    Accessor a = file.grid(0).accessor();
    uint64_t refused = 0, answered = 0;
    for (size_t n = 0; n < c.active.voxels.size(); ++n) {
        const auto& p = c.active.voxels[n];
        for (int again = 0; again < 2; ++again) {
            try {
                const float v = a.value<float>(p[0], p[1], p[2]);
                float want = 0;
                std::memcpy(&want, c.active.voxelValues.data() + n * 4, 4);
                EXPECT_EQ(std::memcmp(&v, &want, 4), 0) << "voxel " << n;
                ++answered;
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find("grid 'density'"), std::string::npos) << e.what();
                ++refused;
            }
        }
    }
    EXPECT_EQ(refused, 2 * c.active.voxels.size() - answered);
    EXPECT_GT(refused, 0u);
    for (const auto& p : c.active.voxels) EXPECT_TRUE(a.isActive(p[0], p[1], p[2]));  // active states need no values
    EXPECT_EQ(a.value<float>(1000, 1000, 1000), 0.0f);  // nor does the background
    std::filesystem::remove(path);
}

TEST(Reader, GridFactsAndTypedValues) {
    std::mt19937 rng(3);
    Case c = shell(ValueType::Float, "density", rng, [](double d, std::mt19937&, uint8_t* out) {
        const float v = float(d);
        std::memcpy(out, &v, 4);
    });
    const auto path = writeFile({{&c, true}}, {}, "reader_facts");
    const File file = File::open(path.string());
    const Grid& g = file.grid("density");
    // Brute force: the box and count of the active voxels and tiles.
    IndexBBox want;
    want.min = {INT64_MAX, INT64_MAX, INT64_MAX};
    want.max = {INT64_MIN, INT64_MIN, INT64_MIN};
    uint64_t count = 0;
    auto grow = [&](int64_t x, int64_t y, int64_t z, int64_t n) {
        const int64_t lo[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            want.min[a] = std::min(want.min[a], lo[a]);
            want.max[a] = std::max(want.max[a], lo[a] + n - 1);
        }
        count += uint64_t(n * n * n);
    };
    for (const auto& v : c.active.voxels) grow(v[0], v[1], v[2], 1);
    for (const Tile& t : c.active.tiles) grow(t.x, t.y, t.z, int64_t(1) << t.log2Size);
    EXPECT_EQ(g.indexBBox().min, want.min);
    EXPECT_EQ(g.indexBBox().max, want.max);
    EXPECT_EQ(g.activeVoxelCount(), count);
    EXPECT_EQ(g.inactiveVoxelCount(), c.inactive.voxels.size() + (uint64_t(1) << 15));
    EXPECT_EQ(g.indexToWorld()[0], 0.5);
    EXPECT_EQ(g.indexToWorld()[12], 1.25);
    EXPECT_EQ(g.background<float>(), 0.0f);
    Accessor a = g.accessor();
    const auto& p = c.active.voxels[100];
    float want100;
    std::memcpy(&want100, c.active.voxelValues.data() + 100 * 4, 4);
    EXPECT_EQ(a.value<float>(p[0], p[1], p[2]), want100);
    EXPECT_THROW(a.value<double>(p[0], p[1], p[2]), Error);
    EXPECT_THROW((void)file.grid("nope"), Error);
    EXPECT_THROW((void)file.grid(7), Error);
    {  // the container header's version (bytes 8-11), and no newer than what the library reads
        std::ifstream in(path, std::ios::binary);
        uint8_t head[12] = {};
        in.read(reinterpret_cast<char*>(head), sizeof head);
        uint32_t version = 0;
        std::memcpy(&version, head + 8, 4);
        EXPECT_EQ(file.formatVersion(), version);
        EXPECT_LE(version, uint32_t(readableFormatVersion()));
        EXPECT_EQ(readableFormatVersion(), 3);
    }
    std::filesystem::remove(path);
}

// OpenLimits (issue 38: one limit mechanism, the library too): a file whose
// layer holds more entries than maxVoxels, or whose sections would take more
// than maxMemory, is refused on open, naming the file; the brute-force count
// of the active voxels and tiles is the threshold.
TEST(Reader, OpenRefusesAFileBeyondItsLimits) {
    std::mt19937 rng(4);
    Case c = shell(ValueType::Float, "density", rng, [](double d, std::mt19937&, uint8_t* out) {
        const float v = float(d);
        std::memcpy(out, &v, 4);
    });
    const auto path = writeFile({{&c, false}}, {}, "reader_limits");  // no inactive layer
    const uint64_t entries = c.active.voxels.size() + c.active.tiles.size();  // a tile is one entry
    ASSERT_GT(entries, 1000u);
    auto refusal = [&](const OpenLimits& limits) -> std::string {
        try {
            (void)File::open(path.string(), limits);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    };
    OpenLimits limits;
    limits.maxVoxels = entries - 1;
    std::string m = refusal(limits);
    EXPECT_EQ(m.rfind(path.string(), 0), 0u) << m;
    EXPECT_NE(m.find("max-voxels"), std::string::npos) << m;
    limits.maxVoxels = entries;
    EXPECT_EQ(refusal(limits), "");
    limits.maxMemory = 1024;  // less than the file's DAG alone
    m = refusal(limits);
    EXPECT_EQ(m.rfind(path.string(), 0), 0u) << m;
    EXPECT_NE(m.find("max-memory"), std::string::npos) << m;
    std::filesystem::remove(path);
}

// value<T> and background<T> take the grid's own C++ type (or a type of
// another name with the value's size, read as its bits); a type of the table
// that is not the grid's is refused (issue 41: value<float> of an int32
// grid returned the int's bits, 7.9e-43 for 564).
TEST(Reader, ValuesAreReadAsTheGridsOwnTypeOnly) {
    std::mt19937 rng(5);
    Case c = shell(ValueType::Int32, "labels", rng, [](double d, std::mt19937&, uint8_t* out) {
        const int32_t v = int32_t(std::lround(d * 100.0)) + 564;
        std::memcpy(out, &v, 4);
    });
    const auto path = writeFile({{&c, false}}, {}, "reader_types");
    const File file = File::open(path.string());
    const Grid& g = file.grid("labels");
    Accessor a = g.accessor();
    const auto& p = c.active.voxels[7];
    int32_t want = 0;
    std::memcpy(&want, c.active.voxelValues.data() + 7 * 4, 4);
    EXPECT_EQ(a.value<int32_t>(p[0], p[1], p[2]), want);
    struct Bits {
        uint8_t b[4];
    };
    const Bits bits = a.value<Bits>(p[0], p[1], p[2]);  // another name, the value's size: its bits
    EXPECT_EQ(std::memcmp(bits.b, &want, 4), 0);
    try {
        (void)a.value<float>(p[0], p[1], p[2]);
        ADD_FAILURE() << "value<float> of an int32 grid was answered";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("asked as float of a int32 grid"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)a.value<int64_t>(p[0], p[1], p[2]), Error);
    EXPECT_THROW((void)g.background<float>(), Error);
    EXPECT_EQ(g.background<int32_t>(), 0);
    std::filesystem::remove(path);
}

TEST(Reader, OpenNamesTheFileInItsError) {
    const std::string missing = (std::filesystem::temp_directory_path() / "no_such_reader_file.ssvdag").string();
    try {
        (void)File::open(missing);
        FAIL() << "opened a missing file";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    const auto junk = std::filesystem::temp_directory_path() / ("reader_junk_" + std::to_string(::getpid()) + ".ssvdag");
    std::ofstream(junk) << "not a DAG";
    EXPECT_THROW((void)File::open(junk.string()), Error);
    std::filesystem::remove(junk);
}

// Grid::sampleBox (the ParaView reader's level of detail): every stride's
// samples, i fastest, equal the brute-force answer at box.min + n * stride;
// a mask grid writes its active states; sampleActive the active states of
// every grid.
TEST(Reader, SampleBoxIsTheBruteForceAnswerAtEveryStride) {
    std::mt19937 rng(5);
    std::vector<Case> cases;
    cases.push_back(shell(ValueType::Float, "float", rng, [](double d, std::mt19937&, uint8_t* out) {
        const float v = float(d);
        std::memcpy(out, &v, 4);
    }));
    cases.push_back(shell(ValueType::Vec3S, "vec3s", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const float v[3] = {float(d), float(r() % 5), -0.0f};
        std::memcpy(out, v, 12);
    }));
    cases.push_back(shell(ValueType::Mask, "mask", rng, [](double, std::mt19937&, uint8_t*) {}));
    std::vector<std::pair<Case*, bool>> grids;
    for (Case& c : cases) grids.push_back({&c, true});
    const auto path = writeFile(grids, {}, "reader_sample_box");
    const File file = File::open(path.string());
    IndexBBox box;
    box.min = {-33, -31, -30};
    box.max = {70, 35, 33};  // through the shell and the 8^3 tiles
    for (size_t g = 0; g < cases.size(); ++g) {
        Reference ref;
        ref.vs = valueSize(cases[g].active.type);
        Reference::add(cases[g].active, ref.vs, ref.active, ref.activeTiles);
        if (ref.vs) Reference::add(cases[g].inactive, ref.vs, ref.inactive, ref.inactiveTiles);
        ref.background.assign(ref.vs, '\0');
        const unsigned row = std::max(1u, ref.vs);
        for (const uint64_t stride : {1u, 2u, 3u, 8u, 200u}) {
            const auto dims = sampleDims(box, stride);
            const uint64_t n = sampleCount(box, stride);
            ASSERT_EQ(n, dims[0] * dims[1] * dims[2]);
            for (int a = 0; a < 3; ++a) EXPECT_EQ(dims[a], uint64_t(box.max[a] - box.min[a]) / stride + 1);
            std::vector<uint8_t> got(n * row);
            file.grid(g).sampleBox(box, stride, got.data());
            uint64_t at = 0, failures = 0;
            for (uint64_t z = 0; z < dims[2]; ++z)
                for (uint64_t y = 0; y < dims[1]; ++y)
                    for (uint64_t x = 0; x < dims[0]; ++x, ++at) {
                        const int64_t i = box.min[0] + int64_t(x * stride), j = box.min[1] + int64_t(y * stride), k = box.min[2] + int64_t(z * stride);
                        const std::string want = ref.vs ? ref.value(i, j, k) : std::string(1, ref.isActive(i, j, k) ? 1 : 0);
                        if (std::memcmp(got.data() + at * row, want.data(), row) != 0 && ++failures <= 3)
                            ADD_FAILURE() << cases[g].name << " stride " << stride << ": sample (" << i << "," << j << "," << k << ") differs";
                    }
            EXPECT_EQ(failures, 0u) << cases[g].name << " stride " << stride;
            std::vector<uint8_t> active(n);
            file.grid(g).sampleActive(box, stride, active.data());
            at = failures = 0;
            for (uint64_t z = 0; z < dims[2]; ++z)
                for (uint64_t y = 0; y < dims[1]; ++y)
                    for (uint64_t x = 0; x < dims[0]; ++x, ++at)
                        if (active[at] != (ref.isActive(box.min[0] + int64_t(x * stride), box.min[1] + int64_t(y * stride), box.min[2] + int64_t(z * stride)) ? 1 : 0))
                            ++failures;
            EXPECT_EQ(failures, 0u) << cases[g].name << " stride " << stride << ": active states";
        }
    }
    EXPECT_EQ(sampleCount(IndexBBox{}, 4), 0u);
    EXPECT_THROW(sampleDims(box, 0), Error);
    IndexBBox huge;
    huge.min = {INT64_MIN / 2, INT64_MIN / 2, INT64_MIN / 2};
    huge.max = {INT64_MAX / 2, INT64_MAX / 2, INT64_MAX / 2};
    EXPECT_THROW(sampleCount(huge, 1), Error);
    std::filesystem::remove(path);
}

// Grid::forEachActive (the ParaView reader's active voxels): the cubes it
// gives, expanded to voxels, are exactly the brute-force active voxels and
// tiles with their values, in the whole grid and in a box (whose
// overlapping cubes come whole); a visitor returning false stops the walk.
TEST(Reader, ForEachActiveGivesTheActiveVoxelsAndTiles) {
    std::mt19937 rng(9);
    std::vector<Case> cases;
    cases.push_back(shell(ValueType::Float, "float", rng, [](double d, std::mt19937& r, uint8_t* out) {
        const float v = (r() % 4 == 0) ? float(r() % 7) : float(d);
        std::memcpy(out, &v, 4);
    }));
    cases.push_back(shell(ValueType::Mask, "mask", rng, [](double, std::mt19937&, uint8_t*) {}));
    std::vector<std::pair<Case*, bool>> grids;
    for (Case& c : cases) grids.push_back({&c, true});
    for (const bool symmetry : {true, false}) {
        pipeline::EncodeOptions options;
        options.symmetry = symmetry;
        const auto path = writeFile(grids, options, symmetry ? "reader_active_ssvdag" : "reader_active_svdag");
        const File file = File::open(path.string());
        for (size_t g = 0; g < cases.size(); ++g) {
            Reference ref;
            ref.vs = valueSize(cases[g].active.type);
            Reference::add(cases[g].active, ref.vs, ref.active, ref.activeTiles);
            IndexBBox everything;
            everything.min = {-1000, -1000, -1000};
            everything.max = {1000, 1000, 1000};
            IndexBBox box;
            box.min = {-5, 3, -40};
            box.max = {80, 30, 2};
            for (const IndexBBox& b : {everything, box}) {
                std::map<std::array<int64_t, 3>, std::string> got;
                uint64_t repeated = 0, cubes = 0;
                file.grid(g).forEachActive(b, [&](const std::array<int64_t, 3>& c, unsigned log2, const void* value) {
                    ++cubes;
                    const int64_t n = int64_t(1) << log2;
                    for (int64_t z = 0; z < n; ++z)
                        for (int64_t y = 0; y < n; ++y)
                            for (int64_t x = 0; x < n; ++x)
                                if (!got.emplace(std::array<int64_t, 3>{c[0] + x, c[1] + y, c[2] + z},
                                                 value ? std::string(static_cast<const char*>(value), ref.vs) : std::string())
                                         .second)
                                    ++repeated;
                    return true;
                });
                EXPECT_EQ(repeated, 0u) << cases[g].name << ": a voxel given twice";
                // Every voxel given is active with its value; every active voxel in the box is given.
                uint64_t wrong = 0, missing = 0;
                for (const auto& [p, v] : got)
                    if (!ref.isActive(p[0], p[1], p[2]) || (ref.vs && v != ref.value(p[0], p[1], p[2]))) ++wrong;
                auto inBox = [&](int64_t x, int64_t y, int64_t z) {
                    return x >= b.min[0] && x <= b.max[0] && y >= b.min[1] && y <= b.max[1] && z >= b.min[2] && z <= b.max[2];
                };
                for (const auto& [p, v] : ref.active)
                    if (inBox(p[0], p[1], p[2]) && !got.count(p)) ++missing;
                for (const auto& [t, v] : ref.activeTiles) {
                    const int64_t n = int64_t(1) << t.log2Size;
                    for (int64_t z = 0; z < n; ++z)
                        for (int64_t y = 0; y < n; ++y)
                            for (int64_t x = 0; x < n; ++x)
                                if (inBox(t.x + x, t.y + y, t.z + z) && !got.count({t.x + x, t.y + y, t.z + z})) ++missing;
                }
                EXPECT_EQ(wrong, 0u) << cases[g].name << ": voxels given that are not active or hold another value";
                EXPECT_EQ(missing, 0u) << cases[g].name << ": active voxels in the box not given";
                EXPECT_GT(cubes, 100u) << cases[g].name;
            }
            uint64_t visits = 0;
            file.grid(g).forEachActive(everything, [&](const std::array<int64_t, 3>&, unsigned, const void*) { return ++visits < 10; });
            EXPECT_EQ(visits, 10u) << cases[g].name << ": the walk did not stop";
        }
        std::filesystem::remove(path);
    }
}
