// The `values` group (issue 7 part 2): special floats and doubles bit-exact
// through the lossless path (quiet and signalling NaNs with payloads, +-Inf,
// -0.0, denormals, FLT_MAX/DBL_MAX); a stiff field spanning 1e-30..1e30
// under --rel-error (the bound holds for every value) and under --abs-error
// (the bound holds too, but every value below E loses all its relative
// precision: absolute tolerances are meaningless there, which the case
// reports); one 1e30 outlier in a field of 0..1 (a range-based quantiser
// would collapse the field; a fixed-step one keeps every value within E); a
// constant field (a handful of bytes for the value channel); two values one
// ulp apart (lossless keeps them apart; a tolerance of one ulp may merge
// them, the bound must still hold); inactive values (level-set signs, NaN
// payloads) bit-exact while a tolerance quantises the active ones.
#include "src/selftest/ValueCases.h"

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include <fmt/core.h>

#include "src/selftest/CaseGroups.h"
#include "src/selftest/FileRoundTrip.h"

namespace vdbdag::selftest {

using attributes::ScalarTolerance;

SyntheticGrid scalarField(ValueType type, const std::vector<uint8_t>& raw) {
    SyntheticGrid grid;
    grid.type = type;
    const unsigned vs = valueSize(type);
    for (size_t i = 0; i * vs < raw.size(); ++i) grid.addVoxel(int32_t(i % 32), int32_t(i / 32 % 32), int32_t(i / 1024), &raw[i * vs]);
    return grid;
}

SyntheticGrid floatField(const std::vector<float>& values) {
    std::vector<uint8_t> raw(values.size() * 4);
    std::memcpy(raw.data(), values.data(), raw.size());
    return scalarField(ValueType::Float, raw);
}

SyntheticGrid doubleField(const std::vector<double>& values) {
    std::vector<uint8_t> raw(values.size() * 8);
    std::memcpy(raw.data(), values.data(), raw.size());
    return scalarField(ValueType::Double, raw);
}

Measurement checkLossless(const SyntheticGrid& field, const std::string& what) {
    const GridRecord record = toRecord(field, what);
    const FileRoundTrip rt = roundTripThroughFile(record);
    const FlatGrid want = flatten(record), got = flatten(rt.decoded);
    Checks checks;
    const std::string diff = firstDifference(want, got);
    checks.require(diff.empty(), diff);
    std::set<std::string> distinct;
    for (const auto& [c, v] : want.voxels) distinct.insert(v);
    const size_t same = diff.empty() ? want.voxels.size() : 0;
    return checks.result(fmt::format("{}/{} identical", same, want.voxels.size()), fmt::format("{} of {} values bit-identical ({} distinct bit patterns), {} file bytes",
                                     same, want.voxels.size(), distinct.size(), rt.fileBytes));
}

namespace {

double valueOf(ValueType type, const std::string& bytes) {
    if (type == ValueType::Float) {
        float f;
        std::memcpy(&f, bytes.data(), 4);
        return double(f);
    }
    double d;
    std::memcpy(&d, bytes.data(), 8);
    return d;
}

} // namespace

ToleranceCheck checkTolerance(const SyntheticGrid& field, const ScalarTolerance& encodeWith, const ScalarTolerance& checkAgainst) {
    ToleranceCheck out;
    const GridRecord record = toRecord(field, "tolerance field");
    pipeline::EncodeOptions options;
    options.tolerance = encodeWith;
    const FileRoundTrip lossy = roundTripThroughFile(record, options);
    out.lossyFileBytes = lossy.fileBytes;
    out.losslessFileBytes = roundTripThroughFile(record).fileBytes;
    const FlatGrid want = flatten(record), got = flatten(lossy.decoded);
    std::set<std::string> before, after;
    for (const auto& [c, wantBytes] : want.voxels) {
        ++out.values;
        before.insert(wantBytes);
        const auto it = got.voxels.find(c);
        const std::string where = fmt::format("voxel ({},{},{})", c[0], c[1], c[2]);
        if (!out.checks.require(it != got.voxels.end(), where + " missing after the round trip")) continue;
        const std::string& gotBytes = it->second;
        after.insert(gotBytes);
        out.changed += gotBytes != wantBytes;
        const double v = valueOf(field.type, wantBytes), q = valueOf(field.type, gotBytes);
        if (!std::isfinite(v) || v == 0.0) {
            out.checks.require(gotBytes == wantBytes, fmt::format("{}: special value {} became {}", where, hexValue(wantBytes), hexValue(gotBytes)));
            continue;
        }
        if (!out.checks.require(std::isfinite(q), fmt::format("{}: {:g} became non-finite {}", where, v, hexValue(gotBytes)))) continue;
        const double err = std::fabs(q - v);
        const double limit = checkAgainst.mode == ScalarTolerance::Mode::Absolute ? checkAgainst.bound
                             : checkAgainst.mode == ScalarTolerance::Mode::Relative ? checkAgainst.bound * std::fabs(v)
                                                                                    : 0.0;
        out.checks.require(err <= limit, fmt::format("{}: {:.17g} became {:.17g}, error {:.3g} > {:.3g}", where, v, q, err, limit));
        out.checks.require(std::signbit(q) == std::signbit(v), fmt::format("{}: {:g} changed sign ({:g})", where, v, q));
        out.maxAbsError = std::max(out.maxAbsError, err);
        const double rel = err / std::fabs(v);
        out.maxRelError = std::max(out.maxRelError, rel);
        out.lostAllPrecision += rel >= 0.5;
    }
    out.checks.require(got.voxels.size() == want.voxels.size(), "the voxel count changed");
    out.distinctBefore = before.size();
    out.distinctAfter = after.size();
    return out;
}

namespace {

template <typename T>
T fromBits(std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t> bits) {
    return std::bit_cast<T>(bits);
}

// Special values of T as bit patterns: quiet NaNs with payloads (both
// signs), signalling NaNs with payloads, +-Inf, +-0, denormals, the extreme
// normals.
std::vector<float> floatSpecials() {
    const uint32_t bits[] = {
        0x7FC00000u, 0x7FC00001u, 0x7FD23456u, 0x7FFFFFFFu, 0xFFC00000u, 0xFFC12345u,  // quiet NaNs
        0x7F800001u, 0x7FA00000u, 0x7FBFFFFFu, 0xFF800001u, 0xFF812345u,               // signalling NaNs
        0x7F800000u, 0xFF800000u,                                                      // +-Inf
        0x00000000u, 0x80000000u,                                                      // +-0
        0x00000001u, 0x00000002u, 0x007FFFFFu, 0x00400000u, 0x80000001u, 0x807FFFFFu,  // denormals
        0x00800000u, 0x80800000u, 0x7F7FFFFFu, 0xFF7FFFFFu, 0x7F7FFFFEu,               // FLT_MIN, FLT_MAX, neighbours
        0x3F800000u, 0x3F800001u,                                                      // 1 and 1 + ulp
    };
    std::vector<float> out;
    for (uint32_t b : bits) out.push_back(fromBits<float>(b));
    return out;
}

std::vector<double> doubleSpecials() {
    const uint64_t bits[] = {
        0x7FF8000000000000ull, 0x7FF8000000000001ull, 0x7FFDEADBEEF00000ull, 0x7FFFFFFFFFFFFFFFull, 0xFFF8000000000000ull,
        0xFFF8000000012345ull,                                                                            // quiet NaNs
        0x7FF0000000000001ull, 0x7FF4000000000000ull, 0x7FF7FFFFFFFFFFFFull, 0xFFF0000000000001ull,     // signalling NaNs
        0x7FF0000000000000ull, 0xFFF0000000000000ull,                                                     // +-Inf
        0x0000000000000000ull, 0x8000000000000000ull,                                                     // +-0
        0x0000000000000001ull, 0x000FFFFFFFFFFFFFull, 0x0008000000000000ull, 0x8000000000000001ull,       // denormals
        0x0010000000000000ull, 0x7FEFFFFFFFFFFFFFull, 0xFFEFFFFFFFFFFFFFull, 0x7FEFFFFFFFFFFFFEull,       // DBL_MIN, DBL_MAX
        0x3FF0000000000000ull, 0x3FF0000000000001ull,                                                     // 1 and 1 + ulp
        0x000000007FC00001ull,                                                                            // a float NaN's bits, as a double
    };
    std::vector<double> out;
    for (uint64_t b : bits) out.push_back(fromBits<double>(b));
    return out;
}

// A field where about half the entries are specials (each appears many
// times, so the palette must treat equal bit patterns as equal even where
// the values compare unequal, NaN != NaN) and half are random values.
template <typename T>
std::vector<T> specialsField(const std::vector<T>& specials, size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1e6, 1e6);
    std::vector<T> out;
    for (size_t i = 0; i < specials.size(); ++i) out.push_back(specials[i]);  // each at least once
    while (out.size() < n) out.push_back((rng() & 1) ? specials[rng() % specials.size()] : T(u(rng)));
    return out;
}

// Magnitudes 10^U(-30, 30) with random signs, plus the values that must stay
// exact (0, -0, NaN with a payload, +-Inf) and the ends of T's range.
template <typename T>
std::vector<T> stiffField(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> exponent(-30.0, 30.0);
    std::vector<T> out{T(0.0), T(-0.0), T(1e-30), T(-1e30), T(1e30), std::numeric_limits<T>::infinity(), -std::numeric_limits<T>::infinity(),
                       std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::max(), -std::numeric_limits<T>::max(),
                       std::numeric_limits<T>::denorm_min(), -std::numeric_limits<T>::min()};
    if constexpr (sizeof(T) == 4) out.push_back(fromBits<float>(0x7FC0BEEFu));
    else out.push_back(fromBits<double>(0x7FF800000000BEEFull));
    while (out.size() < n) out.push_back(T((rng() & 1 ? 1.0 : -1.0) * std::pow(10.0, exponent(rng))));
    return out;
}

template <typename T>
SyntheticGrid fieldOf(const std::vector<T>& v) {
    if constexpr (sizeof(T) == 4) return floatField(v);
    else return doubleField(v);
}

template <typename T>
const char* typeName() { return sizeof(T) == 4 ? "float" : "double"; }

std::string bytesRatio(uint64_t lossy, uint64_t lossless) {
    return fmt::format("file {} B vs {} B lossless ({:.3f}x)", lossy, lossless, double(lossy) / double(std::max<uint64_t>(1, lossless)));
}

template <typename T>
void addTypedCases(std::vector<SelftestCase>& cases) {
    const std::string t = typeName<T>();
    const bool isFloat = sizeof(T) == 4;

    cases.push_back({"values", "specials-lossless-" + t, "bit-exact",
                     "bit-exact: every value's bits unchanged (quiet and signalling NaNs with payloads, +-Inf, -0.0, denormals, " +
                         std::string(isFloat ? "FLT_MAX" : "DBL_MAX") + ")",
                     [] {
                         if constexpr (sizeof(T) == 4) return checkLossless(fieldOf(specialsField(floatSpecials(), 8192, 1)), "specials");
                         else return checkLossless(fieldOf(specialsField(doubleSpecials(), 8192, 2)), "specials");
                     }});

    static constexpr double R = 1e-3;
    cases.push_back({"values", "stiff-rel-" + t, fmt::format("rel err <= {:g}", R),
                     fmt::format("rel-error {:g} on |v| in 1e-30..1e30: |q-v| <= {:g}|v| for every value; 0, -0, NaN, +-Inf bit-exact", R, R),
                     [] {
                         ToleranceCheck c = checkTolerance(fieldOf(stiffField<T>(20000, 3)), {ScalarTolerance::Mode::Relative, R},
                                                           {ScalarTolerance::Mode::Relative, R});
                         return c.checks.result(fmt::format("max rel {:.3g}", c.maxRelError),
                                                fmt::format("max rel error {:.3g}, {} of {} values changed, {} -> {} distinct; {}", c.maxRelError,
                                                            c.changed, c.values, c.distinctBefore, c.distinctAfter,
                                                            bytesRatio(c.lossyFileBytes, c.losslessFileBytes)));
                     }});

    static constexpr double E = 1e-3;
    cases.push_back({"values", "stiff-abs-" + t, fmt::format("abs err <= {:g}", E),
                     fmt::format("abs-error {:g} on |v| in 1e-30..1e30: |q-v| <= {:g} for every value; specials bit-exact "
                                 "(the bound holds but is meaningless below {:g}: reported)",
                                 E, E, E),
                     [] {
                         ToleranceCheck c = checkTolerance(fieldOf(stiffField<T>(20000, 3)), {ScalarTolerance::Mode::Absolute, E},
                                                           {ScalarTolerance::Mode::Absolute, E});
                         return c.checks.result(fmt::format("max abs {:.3g}; {:.1f}% lost all precision", c.maxAbsError,
                                                            100.0 * double(c.lostAllPrecision) / double(c.values)),
                                                fmt::format("max abs error {:.3g}; {} of {} values ({:.1f}%) lost all relative precision "
                                                            "(max rel error {:.3g}); {}",
                                                            c.maxAbsError, c.lostAllPrecision, c.values, 100.0 * double(c.lostAllPrecision) / double(c.values),
                                                            c.maxRelError, bytesRatio(c.lossyFileBytes, c.losslessFileBytes)));
                     }});

    cases.push_back({"values", "outlier-1e30-abs-" + t, fmt::format("abs err <= {:g}", E),
                     fmt::format("abs-error {:g} on 0..1 plus one 1e30: |q-v| <= {:g} for every value (a range-based quantiser "
                                 "would collapse the 0..1 values)",
                                 E, E),
                     [] {
                         std::mt19937_64 rng(4);
                         std::uniform_real_distribution<double> u(0.0, 1.0);
                         std::vector<T> v(8192);
                         for (T& x : v) x = T(u(rng));
                         v[4321] = T(1e30);
                         ToleranceCheck c = checkTolerance(fieldOf(v), {ScalarTolerance::Mode::Absolute, E}, {ScalarTolerance::Mode::Absolute, E});
                         // 0..1 at step 2E leaves about 1/(2E) + 1 levels; collapse would leave a handful.
                         const uint64_t levels = uint64_t(1.0 / (2 * E)) + 1;
                         c.checks.require(c.distinctAfter >= levels / 2,
                                          fmt::format("only {} distinct values survive (expected about {})", c.distinctAfter, levels + 1));
                         return c.checks.result(fmt::format("max abs {:.3g}; {} levels", c.maxAbsError, c.distinctAfter),
                                                fmt::format("max abs error {:.3g}, {} -> {} distinct values (about {} levels + the outlier); {}",
                                                            c.maxAbsError, c.distinctBefore, c.distinctAfter, levels, bytesRatio(c.lossyFileBytes, c.losslessFileBytes)));
                     }});

    static constexpr uint64_t kConstantChannelBound = 64;
    cases.push_back({"values", "constant-" + t, fmt::format("channel <= {} B", kConstantChannelBound),
                     fmt::format("32^3 voxels of one value: bit-exact, value channel <= {} bytes", kConstantChannelBound),
                     [] {
                         SyntheticGrid grid;
                         grid.type = isFloat ? ValueType::Float : ValueType::Double;
                         const T value = T(0.7071067811865476);
                         for (int z = 0; z < 32; ++z)
                             for (int y = 0; y < 32; ++y)
                                 for (int x = 0; x < 32; ++x) grid.addVoxel(x - 16, y, z + 100, &value);
                         const GridRecord record = toRecord(grid, "constant");
                         const FileRoundTrip rt = roundTripThroughFile(record);
                         Checks checks;
                         const std::string diff = firstDifference(flatten(record), flatten(rt.decoded));
                         checks.require(diff.empty(), diff);
                         checks.require(rt.channelBytes() <= kConstantChannelBound,
                                        fmt::format("value channel {} bytes > {}", rt.channelBytes(), kConstantChannelBound));
                         return checks.result(fmt::format("{} B", rt.channelBytes()),
                                              fmt::format("value channel {} bytes ({} materials) for 32768 entries; whole file {} bytes",
                                                          rt.channelBytes(), rt.traceable.materialCount(), rt.fileBytes));
                     }});

    // Two values one ulp apart, alternating.
    auto ulpField = [] {
        const T a = T(1.0), b = std::nextafter(a, T(2.0));
        std::vector<T> v(4096);
        for (size_t i = 0; i < v.size(); ++i) v[i] = (i * 7919 % 3 == 0) ? a : b;
        return v;
    };
    const double ulp = double(std::nextafter(T(1.0), T(2.0))) - 1.0;
    cases.push_back({"values", "one-ulp-lossless-" + t, "bit-exact", "1 and 1 + ulp: bit-exact, both values stay distinct", [ulpField] {
                         return checkLossless(fieldOf(ulpField()), "one ulp");
                     }});
    for (const ScalarTolerance tol : {ScalarTolerance{ScalarTolerance::Mode::Absolute, ulp}, ScalarTolerance{ScalarTolerance::Mode::Relative, ulp}}) {
        const bool abs = tol.mode == ScalarTolerance::Mode::Absolute;
        cases.push_back({"values", std::string("one-ulp-") + (abs ? "abs-" : "rel-") + t, fmt::format("{} err <= 1 ulp", abs ? "abs" : "rel"),
                         fmt::format("1 and 1 + ulp with {}-error {:g} (one ulp): {} for every value (merging them is allowed)",
                                     abs ? "abs" : "rel", ulp, abs ? "|q-v| <= E" : "|q-v| <= R|v|"),
                         [ulpField, tol] {
                             ToleranceCheck c = checkTolerance(fieldOf(ulpField()), tol, tol);
                             return c.checks.result(fmt::format("max abs {:.3g}, {}", c.maxAbsError, c.distinctAfter == 1 ? "merged" : "kept apart"),
                                                    fmt::format("{} -> {} distinct ({}), max abs error {:.3g}", c.distinctBefore, c.distinctAfter,
                                                                c.distinctAfter == 1 ? "merged" : "kept apart", c.maxAbsError));
                         }});
    }
}

// Inactive values (a level set's inside and outside, DESIGN.md invariant 4)
// stay bit-exact even when a tolerance quantises the active values.
void addInactiveCase(std::vector<SelftestCase>& cases) {
    cases.push_back({"values", "inactive-exact-under-abs-float", "inactive bit-exact",
                     "4096 active values in 0..1 with abs-error 0.001, 4096 inactive values (+-0, +-3 level-set signs, NaN payloads, -Inf, "
                     "denormals): every inactive value bit-exact, the active ones within 0.001",
                     [] {
                         std::mt19937_64 rng(8);
                         std::uniform_real_distribution<float> u(0.0f, 1.0f);
                         std::vector<float> active(4096);
                         for (float& x : active) x = u(rng);
                         const float inactiveSet[] = {0.0f, -0.0f, 3.0f, -3.0f, std::bit_cast<float>(0x7FC0ABCDu), std::bit_cast<float>(0x7F800042u),
                                                      -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::denorm_min(), -2.9999998f};
                         SyntheticGrid inactive;
                         for (int i = 0; i < 4096; ++i) inactive.addVoxel(i % 32, i / 32 % 32, -1 - i / 1024, &inactiveSet[rng() % std::size(inactiveSet)]);
                         GridRecord record = toRecord(floatField(active), "level set");
                         GridRecord inactiveRecord = toRecord(inactive, "level set");
                         record.gridClass = "level set";
                         record.inactiveTopology = std::move(inactiveRecord.topology);
                         record.inactiveValues = std::move(inactiveRecord.values);
                         pipeline::EncodeOptions options;
                         options.tolerance = {ScalarTolerance::Mode::Absolute, 1e-3};
                         const FileRoundTrip rt = roundTripThroughFile(record, options);
                         auto inactiveLayer = [](const GridRecord& r) {
                             GridRecord layer = r;
                             layer.topology = r.inactiveTopology;
                             layer.values = r.inactiveValues;
                             return flatten(layer);
                         };
                         Checks checks;
                         const FlatGrid wantInactive = inactiveLayer(record);
                         const std::string diff = firstDifference(wantInactive, inactiveLayer(rt.decoded));
                         const size_t n = wantInactive.voxels.size();
                         checks.require(diff.empty(), "inactive " + diff);
                         const FlatGrid want = flatten(record), got = flatten(rt.decoded);
                         checks.require(want.voxels.size() == got.voxels.size(), "the active voxel count changed");
                         double maxErr = 0;
                         uint64_t changed = 0;
                         for (const auto& [c, bytes] : want.voxels) {
                             const auto it = got.voxels.find(c);
                             if (!checks.require(it != got.voxels.end(), fmt::format("active voxel ({},{},{}) missing", c[0], c[1], c[2]))) continue;
                             const double err = std::fabs(valueOf(ValueType::Float, it->second) - valueOf(ValueType::Float, bytes));
                             checks.require(err <= 1e-3, fmt::format("active voxel ({},{},{}) off by {:.3g}", c[0], c[1], c[2], err));
                             maxErr = std::max(maxErr, err);
                             changed += it->second != bytes;
                         }
                         return checks.result(fmt::format("{}/{} inactive exact", diff.empty() ? n : 0, n),
                                              fmt::format("{} of {} inactive values bit-exact; {} of {} active values quantised, max error {:.3g}",
                                                          diff.empty() ? n : 0, n, changed, want.voxels.size(), maxErr));
                     }});
}

} // namespace

void addValueCases(std::vector<SelftestCase>& cases) {
    addTypedCases<float>(cases);
    addTypedCases<double>(cases);
    addInactiveCase(cases);
}

} // namespace vdbdag::selftest
