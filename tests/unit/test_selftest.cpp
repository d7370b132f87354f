// The stiff and extreme cases (src/selftest/, issue 7 part 2): one GoogleTest
// per registered case, so CI names the failing one; tests that the checks
// can fail (a tampered tolerance, a flipped NaN payload bit, a lost -0.0, a
// missing voxel, a throwing case); and `vdbdag selftest` as a user runs it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/CompactDag.h"
#include "src/selftest/RayCases.h"
#include "src/selftest/Selftest.h"
#include "src/selftest/SyntheticGrid.h"
#include "src/selftest/ValueCases.h"

using namespace vdbdag;
using namespace vdbdag::selftest;
namespace fs = std::filesystem;

namespace {

std::string testName(const std::string& id) {
    std::string out;
    for (char c : id) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return out;
}

std::vector<size_t> caseIndices() {
    std::vector<size_t> v(selftestCases().size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = i;
    return v;
}

class StiffAndExtreme : public ::testing::TestWithParam<size_t> {};

} // namespace

TEST_P(StiffAndExtreme, BoundHolds) {
    const SelftestCase& c = selftestCases().at(GetParam());
    const CaseResult r = runCase(c);
    RecordProperty("measured", r.measured);
    EXPECT_TRUE(r.passed) << r.id() << "\n  bound:    " << r.bound << "\n  measured: " << r.measured;
}

INSTANTIATE_TEST_SUITE_P(Selftest, StiffAndExtreme, ::testing::ValuesIn(caseIndices()),
                         [](const ::testing::TestParamInfo<size_t>& info) { return testName(selftestCases().at(info.param).id()); });

TEST(SelftestRegistry, EveryGroupHasCasesAndIdsAreUnique) {
    std::set<std::string> ids, names, groups;
    for (const SelftestCase& c : selftestCases()) {
        EXPECT_TRUE(ids.insert(c.id()).second) << c.id();
        EXPECT_TRUE(names.insert(testName(c.id())).second) << "two cases share the test name " << testName(c.id());
        EXPECT_FALSE(c.bound.empty()) << c.id();
        EXPECT_FALSE(c.limit.empty()) << c.id();
        EXPECT_TRUE(c.run) << c.id();
        groups.insert(c.group);
    }
    EXPECT_EQ(groups, (std::set<std::string>{"values", "geometry", "colours", "normals", "rays"}));
    EXPECT_EQ(countSelftestCases("values/constant-"), 2u);
    EXPECT_EQ(countSelftestCases("no-such-case"), 0u);
    EXPECT_EQ(countSelftestCases(), selftestCases().size());
}

TEST(SelftestRegistry, AFailedCheckOrAThrowingCaseIsReportedAsAFailure) {
    const SelftestCase failing{"values", "tampered", "x <= 1", "x <= 1", [] {
                                   Checks checks;
                                   checks.require(true, "never shown");
                                   checks.require(2.0 <= 1.0, "x = 2 > 1");
                                   checks.require(3.0 <= 1.0, "x = 3 > 1");
                                   return checks.result("2", "x = 2");
                               }};
    const CaseResult f = runCase(failing);
    EXPECT_FALSE(f.passed);
    EXPECT_EQ(f.bound, "x <= 1");
    EXPECT_NE(f.measured.find("VIOLATED: x = 2 > 1 (+1 more)"), std::string::npos) << f.measured;

    const SelftestCase throwing{"rays", "throws", "no exception", "no exception", []() -> Measurement { throw std::runtime_error("corrupt DAG"); }};
    const CaseResult t = runCase(throwing);
    EXPECT_FALSE(t.passed);
    EXPECT_NE(t.measured.find("corrupt DAG"), std::string::npos);
    EXPECT_EQ(t.value, "threw");

    const SelftestCase passing{"rays", "ok", "1 <= 1", "1 <= 1", [] {
                                   Checks checks;
                                   checks.require(1.0 <= 1.0, "never");
                                   return checks.result("1", "x = 1");
                               }};
    const CaseResult p = runCase(passing);
    EXPECT_TRUE(p.passed);
    EXPECT_EQ(p.measured, "x = 1");
    EXPECT_EQ(p.value, "1");
}

TEST(SelftestValues, ATamperedToleranceIsCaught) {
    // Encode with E, check against E/4: most quantised values are off by more
    // than E/4, and the check must say so.
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> v(4096);
    for (float& x : v) x = float(u(rng));
    using Mode = attributes::ScalarTolerance::Mode;
    const SyntheticGrid field = floatField(v);
    const ToleranceCheck honest = checkTolerance(field, {Mode::Absolute, 1e-3}, {Mode::Absolute, 1e-3});
    EXPECT_TRUE(honest.checks.passed()) << honest.checks.result("", "").measured;
    EXPECT_GT(honest.changed, 4000u);
    const ToleranceCheck tampered = checkTolerance(field, {Mode::Absolute, 1e-3}, {Mode::Absolute, 0.25e-3});
    EXPECT_FALSE(tampered.checks.passed());
    EXPECT_NE(tampered.checks.result("", "").measured.find("VIOLATED"), std::string::npos);

    std::vector<double> stiff(4096);
    for (size_t i = 0; i < stiff.size(); ++i) stiff[i] = std::pow(10.0, -30.0 + 60.0 * u(rng)) * (i % 2 ? -1 : 1);
    const SyntheticGrid stiffField = doubleField(stiff);
    EXPECT_TRUE(checkTolerance(stiffField, {Mode::Relative, 1e-3}, {Mode::Relative, 1e-3}).checks.passed());
    EXPECT_FALSE(checkTolerance(stiffField, {Mode::Relative, 1e-3}, {Mode::Relative, 1e-4}).checks.passed());
    // An absolute tolerance checked as a relative one fails on the small values.
    EXPECT_FALSE(checkTolerance(stiffField, {Mode::Absolute, 1e-3}, {Mode::Relative, 1e-3}).checks.passed());
}

TEST(SelftestValues, TheBruteForceComparisonSeesOneFlippedBit) {
    SyntheticGrid grid;
    const uint32_t bits[] = {0x7FC00001u, 0x80000000u, 0x00000001u, 0x7F800001u};
    for (int i = 0; i < 4; ++i) grid.addVoxel(i, 0, -1, &bits[i]);
    const GridRecord record = toRecord(grid, "specials");
    const FlatGrid want = flatten(record);
    EXPECT_EQ(firstDifference(want, want), "");
    ASSERT_EQ(want.voxels.size(), 4u);

    GridRecord payload = record;  // a NaN payload bit
    payload.values.bricks[0] ^= 1;
    EXPECT_NE(firstDifference(want, flatten(payload)).find("0x7fc00001 became 0x7fc00000"), std::string::npos) << firstDifference(want, flatten(payload));

    GridRecord sign = record;  // -0.0 -> +0.0
    sign.values.bricks[7] = 0;
    EXPECT_NE(firstDifference(want, flatten(sign)).find("voxel (1,0,-1)"), std::string::npos) << firstDifference(want, flatten(sign));

    GridRecord missing = record;  // the last voxel dropped
    missing.topology.bricks[0].mask &= ~(uint64_t(1) << brickBitIndex(3, 0, 3));
    missing.values.bricks.resize(12);
    EXPECT_NE(firstDifference(want, flatten(missing)).find("voxel (3,0,-1) missing"), std::string::npos) << firstDifference(want, flatten(missing));

    GridRecord extra = record;  // a tile appears
    extra.topology.tiles.push_back({64, 64, 64, 6});
    extra.values.tiles.assign(4, 0);
    EXPECT_NE(firstDifference(want, flatten(extra)).find("appeared"), std::string::npos);
}

TEST(SelftestRays, AReferenceThatDisagreesOrATooSmallStepBoundIsCaught) {
    auto compact = [](uint64_t mask) {
        GridTopology topology;
        topology.bricks.push_back({0, 0, 0, mask});
        topology.bricks.push_back({12, 0, 0, 1});
        return encoding::encodeCompact(dag::buildDag(topology), true);
    };
    const encoding::CompactDag full = compact(0xFFFFull), holed = compact(0xFFFEull);
    std::vector<trace::Ray> rays;
    for (int x = 0; x < 4; ++x)
        for (int y = 0; y < 4; ++y) {
            trace::Ray ray;
            ray.origin = {x + 0.5, y + 0.5, -3.0};
            ray.direction = {0.0, -0.0, 1.0};
            rays.push_back(ray);
        }
    const Measurement same = compareRays(full, full, rays, 1000);
    EXPECT_TRUE(same.passed) << same.measured;
    EXPECT_EQ(same.value, "0 mismatches / 16");
    const Measurement differ = compareRays(full, holed, rays, 1000);
    EXPECT_FALSE(differ.passed);
    EXPECT_NE(differ.value, "0 mismatches / 16") << differ.measured;  // the hole, and attribute entries shifted by it
    EXPECT_NE(differ.measured.find("VIOLATED"), std::string::npos);
    // From x = 4.5 across the empty cells to voxel (12,0,0): the walk leaves
    // empty nodes behind, so a bound of 0 steps must fail.
    trace::Ray along;
    along.origin = {4.5, 0.5, 0.5};
    along.direction = {1.0, 0.0, 0.0};
    const std::vector<trace::Ray> one{along};
    const Measurement tight = compareRays(holed, holed, one, 0);
    EXPECT_FALSE(tight.passed) << tight.measured;
}

namespace {

using vdbdag::testing::CommandResult;
inline CommandResult runVdbdag(const std::string& args) { return vdbdag::testing::runCli(args); }

} // namespace

TEST(SelftestCli, RunsAFilteredSetPrintsJsonAndRejectsAnUnknownFilter) {
    CommandResult r = runVdbdag("selftest --filter values/constant- --json");
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["total"], 2);
    EXPECT_EQ(report["failed"], 0);
    for (const auto& c : report["cases"]) {
        EXPECT_EQ(c["group"], "values");
        EXPECT_TRUE(c["passed"].get<bool>());
        EXPECT_FALSE(c["bound"].get<std::string>().empty());
        EXPECT_NE(c["measured"].get<std::string>().find("value channel"), std::string::npos);
    }
    EXPECT_TRUE(r.err.empty()) << "no progress when piped: " << r.err;

    r = runVdbdag("selftest --filter rays/unit-cube");
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("rays/unit-cube-0.49  t = 0.5, 0 mismatches  0 mismatches / 90  PASS"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 of 1 cases passed, 0 failed"), std::string::npos) << r.out;

    r = runVdbdag("selftest --list --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out).size(), selftestCases().size());

    r = runVdbdag("selftest --filter no-such-case");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("no case matches 'no-such-case'"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
}

// Issue 41 item 6: the self-test cases and the test oracles are a library
// of their own that no product links. By nm (binutils): vdbdag, vdbdag-full
// and vdbdag-mpi hold none of their symbols; `vdbdag selftest` still runs,
// through the vdbdag-selftest helper, and lists every case.
TEST(SelftestRegistry, TheProductsLinkNoSelftestCode) {
    const std::filesystem::path dir = std::filesystem::path(VDBDAG_BINARY).parent_path();
    std::vector<std::string> products{"vdbdag", "vdbdag-full"};
    if (std::filesystem::exists(dir / "vdbdag-mpi")) products.push_back("vdbdag-mpi");
    for (const std::string& p : products) {
        const auto r = vdbdag::testing::runShell("nm -C " + (dir / p).string() +
                                                 " | grep -c 'selftest::runCase\\|SyntheticGrid\\|ExactRayReference\\|exactFirstHit' || true");
        EXPECT_EQ(r.out, "0\n") << p << " links self-test code";
    }
    const auto list = vdbdag::testing::runCli("selftest --list --json");
    ASSERT_EQ(list.exitCode, 0) << list.err;
    EXPECT_EQ(nlohmann::json::parse(list.out).size(), vdbdag::selftest::selftestCases().size());
}
