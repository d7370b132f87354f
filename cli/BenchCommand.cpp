// `vdbdag bench IN.vdb -o REPORT_DIR [--sweep quick|default|full]`: every
// lossy setting of vdbdag against the lossless encoding and against the
// tools a user would otherwise pick (OpenVDB, NanoVDB, ZFP), measured in one
// run on the same grid: size, value error, render error (PSNR, SSIM), and
// encode, decode and trace times (median of repeats with the spread). Writes
// report.md/.csv/.json and PNG plots (cli/BenchReport.h). Issue 7; Benthin
// et al. for the reporting, Dado et al. Tables 1-2 and the SSVDAG paper's
// Table 1 for the columns.
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <map>
#include <optional>
#include <cmath>
#include <filesystem>
#include <thread>

#include <fmt/core.h>

#include "app/BenchReport.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "src/bench/ImageMetrics.h"
#include "src/format/TraceableValues.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/CpuRenderer.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/PeerCodecs.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::cli {
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

TimedEncoding timedEncode(const GridRecord& source, const pipeline::EncodeOptions& options, int repeats, double budgetMs) {
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

} // namespace

void addBenchCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output, sweep = "default";
        std::vector<std::string> grids;
        int width = 480, height = 360, repeats = 0;
        double budgetSeconds = 3;
        bool json = false;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("bench", "Measure every lossy setting's error against size and run time, beside OpenVDB, NanoVDB and ZFP");
    cmd->add_option("input", opt->input, "input .vdb file")->required();
    cmd->add_option("-o,--output", opt->output, "report directory (report.md, report.csv, report.json, plots)")->required();
    cmd->add_option("--sweep", opt->sweep, "quick, default or full")->check(CLI::IsMember({"quick", "default", "full"}));
    cmd->add_option("--grid", opt->grids, "only these grids (repeatable)");
    cmd->add_option("--width", opt->width, "render width for trace time and image error")->check(CLI::Range(16, 4096));
    cmd->add_option("--height", opt->height, "render height")->check(CLI::Range(16, 4096));
    cmd->add_option("--repeats", opt->repeats, "timed runs per measurement (default: by sweep)")->check(CLI::Range(1, 50));
    cmd->add_option("--time-budget", opt->budgetSeconds,
                    "seconds per measurement after which no further repeat is timed (at least one run; default 3)")
        ->check(CLI::Range(0.0, 3600.0));
    cmd->add_flag("--json", opt->json, "print the whole report as JSON on stdout");
    cmd->callback([opt, &exitCode] {
        const auto start = Clock::now();
        const Sweep sweep = sweepFor(opt->sweep);
        app::BenchRun run;
        run.input = opt->input;
        run.sweep = opt->sweep;
        run.repeats = opt->repeats ? opt->repeats : sweep.repeats;
        run.budgetSeconds = opt->budgetSeconds;
        const double budgetMs = opt->budgetSeconds * 1000.0;
        run.renderWidth = opt->width;
        run.renderHeight = opt->height;
        run.machine = fmt::format("{} hardware threads", std::thread::hardware_concurrency());
        if (opt->json) setQuiet(true);
        namespace fs = std::filesystem;
        if (fs::exists(opt->output) && !fs::is_directory(opt->output)) throw Error(opt->output + ": exists and is not a directory");
        const Volume volume = bridge::importVdb(opt->input).volume;

        std::vector<size_t> chosen;
        for (size_t g = 0; g < volume.grids.size(); ++g)
            if (opt->grids.empty() || std::find(opt->grids.begin(), opt->grids.end(), volume.grids[g].name) != opt->grids.end()) chosen.push_back(g);
        if (chosen.empty()) throw Error(opt->input + ": no grid to measure" + (opt->grids.empty() ? "" : " with the given --grid names"));

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
                Volume again = bridge::importVdb(opt->input, importOptions).volume;
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
                std::optional<format::EncodedGrid> encoded;
                if (setting.lodPixels > 0) {
                    encoded = *losslessGrid;
                    p.note = "the lossless encoding, traced with an LOD cut-off";
                } else {
                    TimedEncoding timed = timedEncode(setting.options.normalBits ? *withNormals : grid, setting.options, run.repeats, budgetMs);
                    p.bytes = timed.fileBytes;
                    p.encode = timed.encode;
                    p.decode = timed.decode;
                    encoded = std::move(timed.grid);
                    p.traceableBytes = encoded->dag.byteSize() + encoded->values.byteSize();
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
                    if (k == 0) losslessGrid = *encoded;
                }
                // Trace: the CPU renderer's frame, timed; image error against the lossless render.
                if (!encoded->dag.empty()) {
                    const trace::RenderGrid renderGrid = trace::makeRenderGrid(*encoded);
                    const trace::GridFrame frame(renderGrid.indexToWorld);
                    const trace::Camera camera = trace::frameBounds(frame, renderGrid.cellLo, renderGrid.cellHi, opt->width, opt->height);
                    trace::RenderOptions options;
                    options.lodPixels = setting.lodPixels;
                    std::vector<double> traceMs;
                    trace::Image image;
                    trace::RenderStats stats;
                    for (int r = 0; bench::repeatAgain(r, run.repeats, bench::totalMs(traceMs), budgetMs); ++r) {
                        image = trace::renderCpu(renderGrid, camera, options, &stats);
                        traceMs.push_back(stats.milliseconds);
                    }
                    p.trace = bench::summarise(traceMs);
                    p.raysPerSecond = double(stats.primaryRays) / (p.trace.medianMs / 1000.0);
                    if (k == 0) reference = image;
                    if (reference) {
                        p.psnr = bench::psnr(*reference, image);
                        p.ssim = bench::ssim(*reference, image);
                    }
                }
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
            const std::vector<bench::BenchPoint> peerPoints = bridge::measurePeers(opt->input, chosen[n], peers);
            for (bench::BenchPoint p : peerPoints) {
                p.grid = gridName;
                run.points.push_back(p);
            }
            // Matched error: vdbdag with the bound each lossy peer actually reached.
            progress.setLabel(fmt::format("bench '{}': matched error", gridName));
            for (const bench::BenchPoint& peer : peerPoints) {
                if (peer.family != "NanoVDB FpN" && peer.family != "ZFP") continue;
                if (!(peer.maxError > 0) || !scalar) continue;
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
                p.traceableBytes = timed.grid.dag.byteSize() + format::traceableValues(timed.grid).byteSize();
                p.exact = timed.grid.lossy.changed == 0;
                p.maxError = timed.grid.lossy.maxAbsError;
                p.rmsError = timed.grid.lossy.rmsError;
                run.points.push_back(p);
            }
        }
        progress.finish();
        run.seconds = msSince(start) / 1000.0;
        app::writeBenchReport(run, opt->output);
        if (opt->json) {
            printJson(app::benchToJson(run));
        } else {
            fmt::print("bench: {} points on {} grid(s) in {:.0f} s -> {}/report.md\n", run.points.size(), chosen.size(), run.seconds, opt->output);
        }
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
