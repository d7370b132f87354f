// Core DAG tests without OpenVDB: brick reflections against a brute-force
// bit permutation, canonical forms, symmetry merges (including combined
// flips), and build -> compact encode -> decode against a brute-force voxel
// set on random sparse topologies with tiles and int32-extreme coordinates.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "src/dag/DagBuilder.h"
#include "tests/unit/TestInputs.h"
#include "src/dag/Reflection.h"
#include "src/encoding/CompactDag.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/selftest/SyntheticGrid.h"
#include "src/util/Error.h"

using namespace vdbdag;

namespace {

using vdbdag::testing::Voxel;
using vdbdag::testing::topologyFromVoxels;

uint64_t bruteReflect(uint64_t mask, unsigned m) {
    uint64_t out = 0;
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) {
                if (!((mask >> brickBitIndex(x, y, z)) & 1u)) continue;
                const int rx = (m & 1) ? 3 - x : x, ry = (m & 2) ? 3 - y : y, rz = (m & 4) ? 3 - z : z;
                out |= uint64_t(1) << brickBitIndex(rx, ry, rz);
            }
    return out;
}

// Expands a topology into its voxels (tests only: tiles must be small).
std::set<Voxel> voxelsOf(const GridTopology& topo) {
    std::set<Voxel> voxels;
    for (const Brick& b : topo.bricks)
        for (int i = 0; i < 64; ++i)
            if ((b.mask >> i) & 1u) voxels.insert({int64_t(b.x) + (i & 3), int64_t(b.y) + ((i >> 2) & 3), int64_t(b.z) + (i >> 4)});
    for (const Tile& t : topo.tiles) {
        const int64_t n = int64_t(1) << t.log2Size;
        EXPECT_LE(t.log2Size, 6) << "test helper only expands small tiles";
        for (int64_t z = 0; z < n; ++z)
            for (int64_t y = 0; y < n; ++y)
                for (int64_t x = 0; x < n; ++x) voxels.insert({t.x + x, t.y + y, t.z + z});
    }
    return voxels;
}

encoding::CompactDag roundTripCompact(const GridTopology& topo, bool symmetry) {
    dag::BuildOptions options;
    options.symmetry = symmetry;
    const dag::ReducedDag reduced = dag::buildDag(topo, options);
    encoding::CompactDag compact = encoding::encodeCompact(reduced);
    encoding::validateCompact(compact, "test");
    return compact;
}

} // namespace

TEST(BrickReflection, MatchesBruteForcePermutation) {
    std::mt19937_64 rng(42);
    for (int trial = 0; trial < 200; ++trial) {
        const uint64_t mask = rng() & rng();
        for (unsigned m = 0; m < 8; ++m) {
            EXPECT_EQ(dag::reflectBrick(mask, m), bruteReflect(mask, m)) << "m=" << m;
            EXPECT_EQ(dag::reflectBrick(dag::reflectBrick(mask, m), m), mask);
        }
    }
}

TEST(BrickReflection, AllEightReflectionsCanonicaliseAlike) {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 500; ++trial) {
        const uint64_t mask = rng() & rng() & rng();
        if (!mask) continue;
        const auto reference = dag::canonicalBrick(mask, true);
        EXPECT_EQ(dag::reflectBrick(reference.mask, reference.reflection), mask);
        for (unsigned m = 0; m < 8; ++m) {
            const uint64_t reflected = dag::reflectBrick(mask, m);
            const auto form = dag::canonicalBrick(reflected, true);
            EXPECT_EQ(form.mask, reference.mask);
            EXPECT_EQ(dag::reflectBrick(form.mask, form.reflection), reflected);
            // Invariance is a property of the shape, the same for every image.
            EXPECT_EQ(form.invariance, reference.invariance);
        }
    }
}

TEST(BrickReflection, InvarianceSetIsExact) {
    // One voxel at the corner: only the identity keeps it.
    EXPECT_EQ(dag::canonicalBrick(1, true).invariance, 0x01);
    // A full row along x at y=0,z=0: invariant under the x flip only.
    const uint64_t row = 0xF;
    EXPECT_EQ(dag::canonicalBrick(row, true).invariance, 0x03);
    // Voxels (0,0,z=1) and (3,3,z=1): invariant under the combined XY flip only.
    const uint64_t diagonal = (uint64_t(1) << brickBitIndex(0, 0, 1)) | (uint64_t(1) << brickBitIndex(3, 3, 1));
    EXPECT_EQ(dag::canonicalBrick(diagonal, true).invariance, uint8_t((1u << 0) | (1u << 3)));
}

TEST(DagBuilder, EmptyGridHasNoNodes) {
    const dag::ReducedDag reduced = dag::buildDag(GridTopology{});
    EXPECT_TRUE(reduced.empty());
    const encoding::CompactDag compact = encoding::encodeCompact(reduced);
    EXPECT_TRUE(compact.empty());
    EXPECT_NO_THROW(encoding::validateCompact(compact, "empty"));
    EXPECT_TRUE(encoding::decodeTopology(compact).empty());
}

TEST(DagBuilder, AllMirrorImagesOfANodeMergeIncludingCombinedFlipInvariance) {
    // N: an 8^3 node invariant under the XY flip only (brick B at child (0,0,0),
    // its XY image at child (1,1,0)). P: a 16^3 node holding N at child 0 and
    // an asymmetric brick C elsewhere. The 8 reflections of P, placed in
    // separate 16^3 cells, must reduce to ONE unique 16^3 node; this needs the
    // tag of N compared modulo its invariance group {identity, XY}.
    const uint64_t B = (uint64_t(1) << brickBitIndex(0, 0, 0)) | (uint64_t(1) << brickBitIndex(1, 0, 0)) |
                       (uint64_t(1) << brickBitIndex(0, 2, 3));
    ASSERT_EQ(dag::canonicalBrick(B, true).invariance, 0x01);
    std::set<Voxel> P;
    auto addBrick = [&](std::set<Voxel>& s, int64_t ox, int64_t oy, int64_t oz, uint64_t mask) {
        for (int i = 0; i < 64; ++i)
            if ((mask >> i) & 1u) s.insert({ox + (i & 3), oy + ((i >> 2) & 3), oz + (i >> 4)});
    };
    addBrick(P, 0, 0, 0, B);
    addBrick(P, 4, 4, 0, dag::reflectBrick(B, 3));
    addBrick(P, 12, 8, 4, dag::reflectBrick(B, 5));  // makes P asymmetric
    std::set<Voxel> all;
    for (unsigned m = 0; m < 8; ++m)
        for (const auto& [x, y, z] : P) {
            const int64_t rx = (m & 1) ? 15 - x : x, ry = (m & 2) ? 15 - y : y, rz = (m & 4) ? 15 - z : z;
            all.insert({rx + 32 * int64_t(m), ry, rz});  // 16^3 cells far enough apart
        }
    const GridTopology topo = topologyFromVoxels(all);
    dag::BuildOptions options;
    const dag::ReducedDag withSymmetry = dag::buildDag(topo, options);
    ASSERT_GE(withSymmetry.log2Size, 5u);
    EXPECT_EQ(withSymmetry.inner[4 - 3].nodes.size(), 1u) << "the 8 mirror images of P did not merge";
    EXPECT_EQ(withSymmetry.inner[3 - 3].nodes.size(), 2u) << "N (and the node holding only the third brick)";
    options.symmetry = false;
    const dag::ReducedDag plain = dag::buildDag(topo, options);
    EXPECT_EQ(plain.inner[4 - 3].nodes.size(), 8u);
    // And both decode to the input voxels.
    EXPECT_EQ(voxelsOf(encoding::decodeTopology(encoding::encodeCompact(withSymmetry))), all);
    EXPECT_EQ(voxelsOf(encoding::decodeTopology(encoding::encodeCompact(plain))), all);
}

TEST(DagBuilder, RandomSparseSetsRoundTripExactly) {
    std::mt19937_64 rng(1234);
    for (int trial = 0; trial < 30; ++trial) {
        std::set<Voxel> voxels;
        const int clusters = 1 + int(rng() % 5);
        for (int c = 0; c < clusters; ++c) {
            const int64_t cx = int64_t(rng() % 2000) - 1000, cy = int64_t(rng() % 2000) - 1000, cz = int64_t(rng() % 64);
            const int count = int(rng() % 400);
            for (int i = 0; i < count; ++i) voxels.insert({cx + int64_t(rng() % 20), cy + int64_t(rng() % 20), cz + int64_t(rng() % 20)});
        }
        GridTopology topo = topologyFromVoxels(voxels);
        // Tiles at several levels, away from the voxels.
        if (trial % 3 == 0) {
            topo.tiles.push_back({4096, 4096, 0, 3});
            topo.tiles.push_back({4096 + 32, 4096, 32, 5});
            for (int64_t z = 0; z < 32; z += 8)
                for (int64_t x = 0; x < 16; x += 8) {
                    topo.tiles.push_back({int32_t(8192 + x), 8192, int32_t(z), 3});
                    std::set<Voxel> none;
                }
        }
        std::set<Voxel> expected = voxelsOf(topo);
        for (bool symmetry : {true, false}) {
            const encoding::CompactDag compact = roundTripCompact(topo, symmetry);
            const GridTopology decoded = encoding::decodeTopology(compact);
            EXPECT_EQ(voxelsOf(decoded), expected) << "trial " << trial << " symmetry " << symmetry;
            EXPECT_EQ(encoding::decodedSize(compact).activeVoxels, expected.size());
            for (const Tile& t : decoded.tiles) {
                const int64_t size = int64_t(1) << t.log2Size;
                EXPECT_EQ(int64_t(t.x) % size, 0);
            }
        }
    }
}

TEST(DagBuilder, SsvdagDecodesToTheVoxelsOfThePlainSvdagAndIsSmaller) {
    // A sphere shell centred between voxels (-0.5, -0.5, -0.5), so it is
    // mirror-symmetric about planes between voxels; the centred placement
    // puts those planes on node centres.
    std::set<Voxel> voxels;
    for (int64_t z = -40; z <= 40; ++z)
        for (int64_t y = -40; y <= 40; ++y)
            for (int64_t x = -40; x <= 40; ++x) {
                const double r = std::sqrt((x + 0.5) * (x + 0.5) + (y + 0.5) * (y + 0.5) + (z + 0.5) * (z + 0.5));
                if (std::abs(r - 36.0) < 1.5) voxels.insert({x, y, z});
            }
    GridRecord record;
    record.topology = topologyFromVoxels(voxels);
    pipeline::EncodeOptions options;
    options.placementTrials = 2;
    const auto sym = pipeline::encodeGrid(record, options);
    options.symmetry = false;
    const auto plain = pipeline::encodeGrid(record, options);
    EXPECT_EQ(voxelsOf(pipeline::decodeGrid(sym).topology), voxels);
    EXPECT_EQ(voxelsOf(pipeline::decodeGrid(plain).topology), voxels);
    EXPECT_LT(sym.active.dag.byteSize(), plain.active.dag.byteSize() * 6 / 10) << sym.active.dag.byteSize() << " vs " << plain.active.dag.byteSize();
}

TEST(DagBuilder, Int32ExtremesAndHugeTileStayCompact) {
    GridTopology topo;
    const int32_t lo = std::numeric_limits<int32_t>::min(), hi = std::numeric_limits<int32_t>::max();
    topo.bricks.push_back({lo, lo, lo, 1});                                               // voxel (lo,lo,lo)
    topo.bricks.push_back({hi - 3, hi - 3, hi - 3, uint64_t(1) << 63});                   // voxel (hi,hi,hi)
    topo.bricks.push_back({lo, hi - 3, 0, uint64_t(1) << brickBitIndex(0, 3, 0)});       // (lo, hi, 0)
    topo.tiles.push_back({0, 0, 0, 12});                                                  // a 4096^3 active tile
    const auto reduced = dag::buildDag(topo);
    EXPECT_EQ(reduced.log2Size, 32u);
    size_t nodes = reduced.bricks.size();
    for (const auto& l : reduced.inner) nodes += l.nodes.size();
    EXPECT_LT(nodes, 200u) << "tiles must never be expanded";
    const encoding::CompactDag compact = encoding::encodeCompact(reduced);
    encoding::validateCompact(compact, "extremes");
    const GridTopology decoded = encoding::decodeTopology(compact);
    ASSERT_EQ(decoded.tiles.size(), 1u);
    EXPECT_EQ(decoded.tiles[0].log2Size, 12);
    EXPECT_EQ(decoded.tiles[0].x, 0);
    ASSERT_EQ(decoded.bricks.size(), 3u);
    std::set<std::tuple<int32_t, int32_t, int32_t, uint64_t>> got, want;
    for (const Brick& b : decoded.bricks) got.insert({b.x, b.y, b.z, b.mask});
    for (const Brick& b : topo.bricks) want.insert({b.x, b.y, b.z, b.mask});
    EXPECT_EQ(got, want);
    EXPECT_EQ(encoding::decodedSize(compact).activeVoxels, 3u + (uint64_t(1) << 36));
}

TEST(DagBuilder, OutputIsDeterministicAcrossRuns) {
    std::mt19937_64 rng(99);
    std::set<Voxel> voxels;
    for (int i = 0; i < 20000; ++i) voxels.insert({int64_t(rng() % 200), int64_t(rng() % 200), int64_t(rng() % 200)});
    const GridTopology topo = topologyFromVoxels(voxels);
    GridTopology shuffled = topo;
    std::shuffle(shuffled.bricks.begin(), shuffled.bricks.end(), rng);
    const auto a = roundTripCompact(topo, true), b = roundTripCompact(shuffled, true);
    EXPECT_EQ(a.inner, b.inner);
    EXPECT_EQ(a.leaves, b.leaves);
}

TEST(CompactDag, ValidatorRejectsDanglingPointersAndEmptyNodes) {
    std::set<Voxel> voxels{{0, 0, 0}, {9, 9, 9}, {20, 3, 17}};
    encoding::CompactDag compact = roundTripCompact(topologyFromVoxels(voxels), true);
    {
        auto bad = compact;
        bad.leaves.pop_back();
        EXPECT_THROW(encoding::validateCompact(bad, "x"), Error);
    }
    {
        auto bad = compact;
        bad.inner[0] = 0;  // root header: no children
        EXPECT_THROW(encoding::validateCompact(bad, "x"), Error);
    }
    {
        auto bad = compact;
        bad.inner[1] = uint16_t(bad.inner[1] + 1);  // first root pointer: off by one word
        EXPECT_THROW(encoding::validateCompact(bad, "x"), Error);
    }
    {
        auto bad = compact;
        bad.levelStart.pop_back();
        EXPECT_THROW(encoding::validateCompact(bad, "x"), Error);
    }
}

// Attribute offsets at rest (FORMAT.md 6.2): the file's words carry 0 where
// the offsets were, and the reader's restore gives back exactly the words
// the writer laid out (encodeCompact's sums, another code path), on random
// sets with tiles at several levels; a nonzero word at rest, a flag on a
// level without offsets, and an offset wider than its words are refused.
TEST(CompactDag, OffsetsAtRestAreRestoredExactly) {
    std::mt19937_64 rng(77);
    for (int trial = 0; trial < 20; ++trial) {
        std::set<Voxel> voxels;
        for (int i = 0; i < 3000; ++i) voxels.insert({int64_t(rng() % 90), int64_t(rng() % 70), int64_t(rng() % 40)});
        GridTopology topo = topologyFromVoxels(voxels);
        topo.tiles.push_back({128, 0, 0, 3});
        topo.tiles.push_back({160, 32, 0, 5});
        const encoding::CompactDag written = encoding::encodeCompact(dag::buildDag(topo), true);
        encoding::CompactDag read = written;
        read.inner = encoding::innerWordsAtRest(written);
        read.offsetWords = encoding::offsetWordsAtRest(written);
        size_t zeroed = 0;
        for (size_t w = 0; w < read.inner.size(); ++w) {
            if (read.inner[w] != written.inner[w]) {
                EXPECT_EQ(read.inner[w], 0u);
                ++zeroed;
            }
        }
        EXPECT_GT(zeroed, 0u);
        bool flagged = false;
        for (size_t i = 0; i < read.offsetWords.size(); ++i) {
            EXPECT_EQ(read.offsetWords[i] & ~encoding::kOffsetsAtRest, written.offsetWords[i]);
            flagged |= (read.offsetWords[i] & encoding::kOffsetsAtRest) != 0;
        }
        ASSERT_TRUE(flagged);
        encoding::CompactDag restored = read;
        ASSERT_NO_THROW(encoding::validateAndRestoreOffsets(restored, "at rest"));
        EXPECT_EQ(restored.inner, written.inner);
        EXPECT_EQ(restored.offsetWords, written.offsetWords);
        // A file of before (offsets stored, no flag) reads as it is.
        encoding::CompactDag old = written;
        ASSERT_NO_THROW(encoding::validateAndRestoreOffsets(old, "stored"));
        EXPECT_EQ(old.inner, written.inner);
        if (trial == 0) {
            // A word at rest that is not 0.
            for (size_t w = 0; w < read.inner.size(); ++w)
                if (read.inner[w] != written.inner[w]) {
                    encoding::CompactDag bad = read;
                    bad.inner[w] = 1;
                    EXPECT_THROW(encoding::validateAndRestoreOffsets(bad, "x"), Error);
                    break;
                }
            // The flag on a level without offsets.
            encoding::CompactDag bad = read;
            bad.offsetWords[0] = encoding::kOffsetsAtRest;
            EXPECT_THROW(encoding::validateAndRestoreOffsets(bad, "x"), Error);
        }
    }
}

TEST(SsvdagFile, SceneRoundTripsThroughSections) {
    std::set<Voxel> voxels;
    for (int i = 0; i < 100; ++i) voxels.insert({i, i / 2, -i});
    GridRecord record;
    record.name = "ramp";
    record.gridClass = "fog volume";
    record.valueType = ValueType::Float;
    record.vdbDescriptor = {1, 2, 3};
    record.background = {0, 0, 0, 0};
    record.topology = topologyFromVoxels(voxels);
    for (size_t i = 0; i < voxels.size(); ++i) {
        const float v = float(i) * 0.5f - 7.0f;
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        record.values.bricks.insert(record.values.bricks.end(), p, p + 4);
    }
    pipeline::EncodeOptions options;
    options.computeSvdagStats = true;
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record, options));
    scene.grids.push_back(pipeline::encodeGrid(GridRecord{}, options));  // empty grid, empty name
    const auto bytes = format::writeScene(scene);
    const format::SsvdagScene back = format::readScene(bytes, "mem");
    ASSERT_EQ(back.grids.size(), 2u);
    EXPECT_EQ(back.grids[0].record.name, "ramp");
    EXPECT_EQ(back.grids[0].record.gridClass, "fog volume");
    EXPECT_EQ(back.grids[0].record.vdbDescriptor, record.vdbDescriptor);
    EXPECT_EQ(back.grids[0].active.voxels, voxels.size());
    EXPECT_TRUE(back.grids[0].stats.hasSvdag);
    const GridRecord decoded = pipeline::decodeGrid(back.grids[0]);
    EXPECT_EQ(voxelsOf(decoded.topology), voxels);
    EXPECT_EQ(decoded.values.bricks.size(), record.values.bricks.size());
    EXPECT_TRUE(back.grids[1].active.dag.empty());
    EXPECT_EQ(back.grids[1].record.name, "");
}

// --placement-trials N keeps the candidate whose file is smallest: the
// candidates for N are those for N-1 and one more, so the written file
// (geometry, values and the placement's small tables) can never grow with
// N. The placement orders the values too: a criterion that weighs only the
// geometry (the one before) fails this at 6 trials here, the file growing by
// 123 bytes. Every file decodes to the input (brute-force flatten).
TEST(DagBuilder, MorePlacementTrialsNeverEnlargeTheFile) {
    for (const double tilt : {0.3, 0.7}) {
        selftest::SyntheticGrid torus, inside;  // a torus (R 30, r 4) tilted about the x axis, its signed distances
        const double c = std::cos(tilt), s = std::sin(tilt);
        for (int z = -40; z <= 40; ++z)
            for (int y = -40; y <= 40; ++y)
                for (int x = -40; x <= 40; ++x) {
                    const double yy = c * double(y) - s * double(z), zz = s * double(y) + c * double(z);
                    const double q = std::sqrt(double(x * x) + yy * yy) - 30.0;
                    const double d = std::sqrt(q * q + zz * zz) - 4.0;
                    const float v = float(d);  // a signed distance, as a level set holds
                    if (std::abs(d) < 1.0) torus.addVoxel(x, y, z, &v);
                    else if (d < 0) inside.addVoxel(x, y, z, &v);
                }
        GridRecord record = selftest::toRecord(torus, "torus");
        const GridRecord in = selftest::toRecord(inside, "inside");
        record.inactiveTopology = in.topology;
        record.inactiveValues = in.values;
        uint64_t previous = 0;
        for (int trials = 1; trials <= 8; ++trials) {
            pipeline::EncodeOptions options;
            options.placementTrials = trials;
            options.computeSvdagStats = true;
            format::SsvdagScene scene;
            scene.grids.push_back(pipeline::encodeGrid(record, options));
            const uint64_t bytes = format::writeScene(scene).size();
            if (trials > 1) { EXPECT_LE(bytes, previous) << "tilt " << tilt << ", " << trials << " trials"; }
            previous = bytes;
            EXPECT_EQ(selftest::firstDifference(selftest::flatten(record), selftest::flatten(pipeline::decodeGrid(scene.grids[0]))), "")
                << "tilt " << tilt << ", " << trials << " trials";
        }
    }
}
