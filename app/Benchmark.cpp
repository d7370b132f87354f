// See Benchmark.h. Issue 7; Benthin et al. for the reporting, Dado et al.
// Tables 1-2 and the SSVDAG paper's Table 1 for the columns.
#include "app/Benchmark.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <thread>

#include <fmt/core.h>

#include "src/bench/ImageMetrics.h"
#include "src/format/TraceableValues.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/CpuRenderer.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/PeerCodecs.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::app {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

struct Setting {
    std::string name, family;
    pipeline::EncodeOptions options;
    double lodPixels = 0;  // > 0: the lossless encoding rendered with this LOD cut-off
    std::string metric = bench::kValueError;
};

struct Sweep {
    int repeats;
    std::vector<double> absFractions;  // of the largest |value|
    std::vector<double> relBounds;
    std::vector<double> lodPixels;
    std::vector<unsigned> colourBits;  // colour grids: at most 2^k colours (Dado et al. Table 2)
    std::vector<unsigned> normalBits;  // level sets: k-bit ONV normals (Dado et al. Table 5)
};

Sweep sweepFor(const std::string& name) {
    if (name == "quick") return {1, {1e-1, 1e-2}, {1e-2}, {2}, {12}, {16}};
    if (name == "full") return {5, {1e-1, 1e-2, 1e-3, 1e-4, 1e-5}, {1e-2, 1e-3, 1e-4, 1e-5}, {1, 2, 4, 8}, {16, 14, 12, 10, 8}, {32, 24, 16, 12, 10}};
    return {3, {1e-1, 1e-2, 1e-3}, {1e-2, 1e-3, 1e-4}, {1, 2, 4}, {14, 12, 10}, {32, 16, 12, 10}};
}

// Level sets get the ONV-normal rows: their normals are the gradient.
bool takesNormals(const GridRecord& grid) {
    return grid.gridClass == "level set" && (grid.valueType == ValueType::Float || grid.valueType == ValueType::Double);
}

// Largest finite |value| of a float/double grid's active values (0 otherwise).
double largestMagnitude(const GridRecord& grid) {
    double largest = 0;
    auto scan = [&](const std::vector<uint8_t>& bytes) {
        if (grid.valueType == ValueType::Float)
            for (size_t i = 0; i + 4 <= bytes.size(); i += 4) { float f; std::memcpy(&f, &bytes[i], 4); if (std::isfinite(f)) largest = std::max(largest, double(std::fabs(f))); }
        if (grid.valueType == ValueType::Double)
            for (size_t i = 0; i + 8 <= bytes.size(); i += 8) { double d; std::memcpy(&d, &bytes[i], 8); if (std::isfinite(d)) largest = std::max(largest, std::fabs(d)); }
    };
    scan(grid.values.bricks);
    scan(grid.values.tiles);
    return largest;
}

std::string roundTolerance(double v) { return fmt::format("{:.2g}", v); }

// One setting's encoding, timed: encode + write, then read + decode, repeated
// within the budget (bench::repeatAgain). Keeps the last run's encoding.
struct TimedEncoding {
    format::EncodedGrid grid;
    uint64_t fileBytes = 0;
    bench::Timing encode, decode;
};

TimedEncoding timedEncode(const GridRecord& source, pipeline::EncodeOptions options, int repeats, double budgetMs) {
    options.keepAttributes = false;  // the timed encode writes the file; the reader's grid is kept
    TimedEncoding out;
    std::vector<double> encodeMs, decodeMs;
    for (int r = 0; bench::repeatAgain(r, repeats, bench::totalMs(encodeMs) + bench::totalMs(decodeMs), budgetMs); ++r) {
        auto t0 = Clock::now();
        format::SsvdagScene scene;
        scene.grids.push_back(pipeline::encodeGrid(source, options));
        const std::vector<uint8_t> bytes = format::writeScene(scene);
        encodeMs.push_back(msSince(t0));
        t0 = Clock::now();
        format::SsvdagScene back = format::readScene(bytes, "bench");
        pipeline::decodeGrid(back.grids.front());
        decodeMs.push_back(msSince(t0));
        out.fileBytes = bytes.size();
        out.grid = std::move(back.grids.front());  // as a reader has it: with the traceable value channel
    }
    out.encode = bench::summarise(encodeMs);
    out.decode = bench::summarise(decodeMs);
    return out;
}

// One setting's point: its encoding timed (or, for an LOD row, the lossless
// one), its value, colour or normal error, and its trace timed and compared
// with the first setting's render (the lossless one, kept in `reference`;
// `losslessGrid` keeps its encoding for the LOD rows).
void measureSetting(bench::BenchPoint& p, const Setting& setting, const GridRecord& source, int repeats, double budgetMs, int width, int height, bool first,
                    std::optional<format::EncodedGrid>& losslessGrid, std::optional<trace::Image>& reference) {
    std::optional<format::EncodedGrid> encoded;
    if (setting.lodPixels > 0) {
        encoded = *losslessGrid;
        p.note = "the lossless encoding, traced with an LOD cut-off";
    } else {
        TimedEncoding timed = timedEncode(source, setting.options, repeats, budgetMs);
        p.bytes = timed.fileBytes;
        p.encode = timed.encode;
        p.decode = timed.decode;
        encoded = std::move(timed.grid);
        p.traceableBytes = encoded->active.dag.byteSize() + encoded->active.values.byteSize();
        const auto& lossy = encoded->lossy;
        p.exact = lossy.changed == 0;
        p.maxError = lossy.maxAbsError;
        p.rmsError = lossy.rmsError;
        if (lossy.tolerance.mode != attributes::ScalarTolerance::Mode::Exact)
            p.note = fmt::format("{} of {} values changed; max rel error {:.3g}", lossy.changed, lossy.entries, lossy.maxRelError);
        if (encoded->colour) {  // Dado et al.'s colour metrics: ΔE94, and per channel in 0..255 units
            const attributes::ColourReport& c = *encoded->colour;
            p.exact = c.changed == 0;
            p.maxError = c.maxDeltaE94;
            p.meanError = c.meanDeltaE94;
            p.rmsError = std::numeric_limits<double>::quiet_NaN();
            p.note = fmt::format("{} -> {} distinct colours, {} of {} entries changed; max |d| R,G,B {:.2f}, {:.2f}, {:.2f} of 255",
                                 c.distinctBefore, c.distinctAfter, c.changed, c.entries, c.maxAbsError[0], c.maxAbsError[1],
                                 c.maxAbsError[2]);
        }
        if (encoded->normals) {  // angle between the stored ONV and the exact gradient normal
            const attributes::NormalReport& nr = encoded->normals->report;
            p.exact = false;
            p.maxError = nr.maxAngleDegrees;
            p.meanError = nr.meanAngleDegrees;
            p.rmsError = std::numeric_limits<double>::quiet_NaN();
            p.note = fmt::format("values exact; {} normals ({} without direction); render against the lossless render (gradient normals)",
                                 nr.entries, nr.zeroLength);
        }
        if (first) losslessGrid = *encoded;
    }
    // Trace: the CPU renderer's frame, timed; image error against the lossless render.
    if (!encoded->active.dag.empty()) {
        const trace::RenderGrid renderGrid = trace::makeRenderGrid(*encoded);
        const trace::GridFrame frame(renderGrid.indexToWorld);
        const trace::Camera camera = trace::frameBounds(frame, renderGrid.cellLo, renderGrid.cellHi, width, height);
        trace::RenderOptions options;
        options.lodPixels = setting.lodPixels;
        std::vector<double> traceMs;
        trace::Image image;
        trace::RenderStats stats;
        for (int r = 0; bench::repeatAgain(r, repeats, bench::totalMs(traceMs), budgetMs); ++r) {
            image = trace::renderCpu(renderGrid, camera, options, &stats);
            traceMs.push_back(stats.milliseconds);
        }
        p.trace = bench::summarise(traceMs);
        p.raysPerSecond = double(stats.primaryRays) / (p.trace.medianMs / 1000.0);
        if (first) reference = image;
        if (reference) {
            p.psnr = bench::psnr(*reference, image);
            p.ssim = bench::ssim(*reference, image);
        }
    }
}

// vdbdag with the bound each lossy peer (NanoVDB FpN, ZFP) actually reached,
// beside it: the sweep's point again where it already encoded that bound.
void addMatchedPoints(BenchRun& run, const std::vector<bench::BenchPoint>& peerPoints, const GridRecord& grid, const std::string& gridName,
                      const std::map<double, std::string>& absSettingOf, double budgetMs) {
    const uint64_t voxels = grid.topology.activeVoxelCount();
    for (const bench::BenchPoint& peer : peerPoints) {
        if (peer.family != "NanoVDB FpN" && peer.family != "ZFP") continue;
        if (!(peer.maxError > 0)) continue;
        pipeline::EncodeOptions options;
        options.tolerance = {attributes::ScalarTolerance::Mode::Absolute, peer.maxError};
        bench::BenchPoint p;
        p.grid = gridName;
        p.tool = "vdbdag";
        p.setting = fmt::format("abs {:.3g}", peer.maxError);
        p.family = "vdbdag matched";
        p.activeVoxels = voxels;
        p.rawBytes = voxels * valueSize(grid.valueType);
        p.note = "matched to " + peer.tool + " " + peer.setting;
        // The sweep already encoded this bound (FpN usually reaches its tolerance exactly): the same point again.
        const auto bound = absSettingOf.find(peer.maxError);
        const auto same = bound == absSettingOf.end() ? run.points.end()
                                                      : std::find_if(run.points.begin(), run.points.end(), [&](const bench::BenchPoint& q) {
                                                            return q.grid == gridName && q.setting == bound->second;
                                                        });
        if (same != run.points.end()) {
            bench::BenchPoint copy = *same;
            copy.setting = p.setting;
            copy.family = p.family;
            copy.note = p.note + " (the sweep's point with this bound)";
            copy.psnr = copy.ssim = copy.raysPerSecond = std::numeric_limits<double>::quiet_NaN();
            copy.trace = {};
            run.points.push_back(copy);
            continue;
        }
        const TimedEncoding timed = timedEncode(grid, options, run.repeats, budgetMs);
        p.bytes = timed.fileBytes;
        p.encode = timed.encode;
        p.decode = timed.decode;
        p.traceableBytes = timed.grid.active.dag.byteSize() + format::traceableValues(timed.grid).byteSize();
        p.exact = timed.grid.lossy.changed == 0;
        p.maxError = timed.grid.lossy.maxAbsError;
        p.rmsError = timed.grid.lossy.rmsError;
        run.points.push_back(p);
    }
}

} // namespace

BenchRun runBenchmark(const BenchRequest& request) {
    const auto start = Clock::now();
    const Sweep sweep = sweepFor(request.sweep);
    BenchRun run;
    run.input = request.input;
    run.sweep = request.sweep;
    run.repeats = request.repeats ? request.repeats : sweep.repeats;
    run.budgetSeconds = request.budgetSeconds;
    const double budgetMs = request.budgetSeconds * 1000.0;
    run.renderWidth = request.width;
    run.renderHeight = request.height;
    run.machine = fmt::format("{} hardware threads", std::thread::hardware_concurrency());
    namespace fs = std::filesystem;
    const Volume volume = bridge::importVdb(request.input).volume;

    std::vector<size_t> chosen;
    for (size_t g = 0; g < volume.grids.size(); ++g)
        if (request.grids.empty() || std::find(request.grids.begin(), request.grids.end(), volume.grids[g].name) != request.grids.end()) chosen.push_back(g);
    if (chosen.empty()) throw Error(request.input + ": no grid to measure" + (request.grids.empty() ? "" : " with the given --grid names"));

    const fs::path scratch = fs::temp_directory_path() / fmt::format("vdbdag-bench-{}", ::getpid());
    fs::create_directories(scratch);
    struct Cleanup { fs::path p; ~Cleanup() { std::error_code ec; fs::remove_all(p, ec); } } cleanup{scratch};

    Progress progress("bench", chosen.size() * 100);
    for (size_t n = 0; n < chosen.size(); ++n) {
        const GridRecord& grid = volume.grids[chosen[n]];
        const std::string gridName = grid.name.empty() ? fmt::format("grid{}", chosen[n]) : grid.name;
        const bool scalar = grid.valueType == ValueType::Float || grid.valueType == ValueType::Double;
        const double largest = scalar ? largestMagnitude(grid) : 0;
        const uint64_t voxels = grid.topology.activeVoxelCount();

        std::vector<Setting> settings;
        settings.push_back({"lossless", "vdbdag", {}, 0});
        Setting plain{"lossless, no symmetry (SVDAG)", "vdbdag", {}, 0};
        plain.options.symmetry = false;
        settings.push_back(plain);
        Setting wide{"lossless, no pointer compaction", "vdbdag", {}, 0};
        wide.options.compactPointers = false;
        settings.push_back(wide);
        std::vector<double> absTolerances;
        std::map<double, std::string> absSettingOf;  // the sweep's absolute bounds -> their setting names
        if (scalar && largest > 0) {
            for (double f : sweep.absFractions) {
                const double tolerance = std::stod(roundTolerance(largest * f));
                absTolerances.push_back(tolerance);
                Setting s{fmt::format("abs {}", roundTolerance(tolerance)), "vdbdag abs", {}, 0};
                absSettingOf[tolerance] = s.name;
                s.options.tolerance = {attributes::ScalarTolerance::Mode::Absolute, tolerance};
                settings.push_back(s);
            }
            for (double r : sweep.relBounds) {
                Setting s{fmt::format("rel {:g}", r), "vdbdag rel", {}, 0};
                s.options.tolerance = {attributes::ScalarTolerance::Mode::Relative, r};
                settings.push_back(s);
            }
        }
        pipeline::EncodeOptions colourProbe;
        colourProbe.colourBits = 8;
        if (pipeline::isColourGrid(grid, colourProbe))
            for (unsigned bits : sweep.colourBits) {
                Setting s{fmt::format("colour {} bits", bits), "vdbdag colour", {}, 0, bench::kColourError};
                s.options.colourBits = bits;
                settings.push_back(s);
            }
        // The exact gradient normals, imported once for this grid only
        // (their computation is import work, not counted in encode time).
        std::optional<GridRecord> withNormals;
        if (takesNormals(grid) && !sweep.normalBits.empty()) {
            bridge::ImportOptions importOptions;
            importOptions.onlyGrids = {grid.name};
            importOptions.normals = true;
            Volume again = bridge::importVdb(request.input, importOptions).volume;
            // Names may repeat: take the grid of the same rank among its namesakes (both imports keep file order).
            size_t rank = 0;
            for (size_t g = 0; g < chosen[n]; ++g) rank += volume.grids[g].name == grid.name;
            for (GridRecord& g : again.grids)
                if (g.name == grid.name && rank-- == 0) {
                    if (g.normals) withNormals = std::move(g);
                    break;
                }
            if (withNormals)
                for (unsigned bits : sweep.normalBits) {
                    Setting s{fmt::format("normals ONV {} bits", bits), "vdbdag normals", {}, 0, bench::kNormalError};
                    s.options.normalBits = bits;
                    settings.push_back(s);
                }
        }
        for (double px : sweep.lodPixels) settings.push_back({fmt::format("LOD {:g} px", px), "vdbdag lod", {}, px});

        const size_t steps = settings.size() + 1;
        auto tick = [&](size_t k) { progress.set(n * 100 + k * 100 / steps); };
        progress.setLabel(fmt::format("bench '{}'", gridName));

        std::optional<trace::Image> reference;
        std::optional<format::EncodedGrid> losslessGrid;
        for (size_t k = 0; k < settings.size(); ++k) {
            tick(k);
            const Setting& setting = settings[k];
            bench::BenchPoint p;
            p.grid = gridName;
            p.tool = "vdbdag";
            p.setting = setting.name;
            p.family = setting.family;
            p.metric = setting.metric;
            p.activeVoxels = voxels;
            p.rawBytes = voxels * valueSize(grid.valueType);
            measureSetting(p, setting, setting.options.normalBits ? *withNormals : grid, run.repeats, budgetMs, request.width, request.height, k == 0,
                           losslessGrid, reference);
            run.points.push_back(p);
        }
        // LOD rows share the lossless encoding's size.
        for (auto& p : run.points)
            if (p.grid == gridName && p.family == "vdbdag lod")
                for (const auto& q : run.points)
                    if (q.grid == gridName && q.setting == "lossless") { p.bytes = q.bytes; p.traceableBytes = q.traceableBytes; }

        tick(settings.size());
        progress.setLabel(fmt::format("bench '{}': peers", gridName));
        bridge::PeerOptions peers;
        peers.absTolerances = absTolerances;
        peers.repeats = run.repeats;
        peers.budgetMs = budgetMs;
        peers.scratchDirectory = scratch.string();
        const std::vector<bench::BenchPoint> peerPoints = bridge::measurePeers(request.input, chosen[n], peers);
        for (bench::BenchPoint p : peerPoints) {
            p.grid = gridName;
            run.points.push_back(p);
        }
        // Matched error: vdbdag with the bound each lossy peer actually reached.
        progress.setLabel(fmt::format("bench '{}': matched error", gridName));
        if (scalar) addMatchedPoints(run, peerPoints, grid, gridName, absSettingOf, budgetMs);
    }
    progress.finish();
    run.seconds = msSince(start) / 1000.0;
    run.gridCount = chosen.size();
    return run;
}

} // namespace vdbdag::app
