// Report files of `vdbdag bench`; see BenchReport.h.
#include "app/BenchReport.h"

#include "app/ReportVersions.h"


#include <cmath>
#include <limits>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/core.h>

#include "src/util/AtomicFile.h"
#include "vdb_bridge/PlotWriter.h"

namespace vdbdag::app {
namespace {

nlohmann::json timingJson(const bench::Timing& t) {
    if (!t.measured()) return nullptr;
    return {{"median_ms", t.medianMs}, {"min_ms", t.minMs}, {"max_ms", t.maxMs}, {"runs", t.runs}};
}

nlohmann::json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string fmtTiming(const bench::Timing& t) {
    if (!t.measured()) return "–";
    if (t.runs == 1) return fmt::format("{:.1f}", t.medianMs);
    return fmt::format("{:.1f} [{:.1f}–{:.1f}]", t.medianMs, t.minMs, t.maxMs);
}

std::string fmtError(const bench::BenchPoint& p, double e) {
    if (p.exact) return "exact";
    return fmt::format("{:.3g}", e);
}

std::string fmtOptional(double v, const char* format) {
    if (std::isinf(v) && v > 0) return "∞";
    return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "–";
}

std::vector<std::string> gridsOf(const BenchRun& run) {
    std::vector<std::string> grids;
    for (const auto& p : run.points)
        if (std::find(grids.begin(), grids.end(), p.grid) == grids.end()) grids.push_back(p.grid);
    return grids;
}

std::vector<size_t> pointsOf(const BenchRun& run, const std::string& grid) {
    std::vector<size_t> ids;
    for (size_t i = 0; i < run.points.size(); ++i)
        if (run.points[i].grid == grid) ids.push_back(i);
    return ids;
}

// Metrics present among `ids`, the value error first.
std::vector<std::string> metricsOf(const BenchRun& run, const std::vector<size_t>& ids) {
    std::vector<std::string> metrics;
    for (size_t i : ids)
        if (std::find(metrics.begin(), metrics.end(), run.points[i].metric) == metrics.end()) metrics.push_back(run.points[i].metric);
    std::stable_partition(metrics.begin(), metrics.end(), [](const std::string& m) { return m == bench::kValueError; });
    return metrics;
}

// The points of one metric: errors of different metrics are not comparable.
// Colour rows are also compared with the lossless point (exact colours,
// error 0); normal rows only among themselves (lossless stores no normals).
std::vector<size_t> comparable(const BenchRun& run, const std::vector<size_t>& ids, const std::string& metric) {
    std::vector<size_t> out;
    for (size_t i : ids) {
        const auto& p = run.points[i];
        if (p.metric == metric || (metric == bench::kColourError && p.tool == "vdbdag" && p.setting == "lossless")) out.push_back(i);
    }
    return out;
}

// Front over (x, max error), exact points counting as error 0.
std::set<size_t> frontOf(const BenchRun& run, const std::vector<size_t>& ids, bool byTime) {
    std::vector<double> x, y;
    for (size_t i : ids) {
        const auto& p = run.points[i];
        const bool sameEncoding = p.family == "vdbdag lod";  // the lossless bytes again: not a point of its own
        x.push_back(sameEncoding ? std::numeric_limits<double>::quiet_NaN() : byTime ? p.decode.medianMs : double(p.bytes));
        y.push_back(p.exact ? 0.0 : p.maxError);
    }
    std::set<size_t> front;
    for (size_t k : bench::paretoFront(x, y)) front.insert(ids[k]);
    return front;
}

std::array<float, 3> familyColour(const std::string& family) {
    static const std::map<std::string, std::array<float, 3>> colours{
        {"vdbdag", {0.84f, 0.15f, 0.16f}},      {"vdbdag abs", {0.89f, 0.47f, 0.76f}}, {"vdbdag rel", {0.55f, 0.34f, 0.29f}},
        {"vdbdag lod", {0.58f, 0.40f, 0.74f}},  {"OpenVDB", {0.12f, 0.47f, 0.71f}},    {"NanoVDB", {0.17f, 0.63f, 0.17f}},
        {"NanoVDB Fp", {0.60f, 0.80f, 0.20f}},  {"NanoVDB FpN", {0.00f, 0.40f, 0.00f}}, {"ZFP", {1.00f, 0.50f, 0.05f}}, {"vdbdag matched", {0.98f, 0.60f, 0.60f}},
        {"vdbdag colour", {0.09f, 0.75f, 0.81f}}, {"vdbdag normals", {0.74f, 0.74f, 0.13f}}};
    const auto it = colours.find(family);
    return it != colours.end() ? it->second : std::array<float, 3>{0.5f, 0.5f, 0.5f};
}

std::string fileSafe(std::string s) {
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s.empty() ? "unnamed" : s;
}

std::string errorLabel(const std::string& metric) {
    if (metric == bench::kColourError) return "max colour error (CIELAB dE94)";
    if (metric == bench::kNormalError) return "max normal error (degrees)";
    return "max abs error";
}

void plot(const BenchRun& run, const std::vector<size_t>& ids, bool byTime, const std::string& path, const std::string& grid,
          const std::string& metric) {
    std::vector<bridge::PlotSeries> series;
    std::map<std::string, size_t> seriesOf;
    std::map<size_t, std::pair<size_t, size_t>> where;
    for (size_t i : ids) {
        const auto& p = run.points[i];
        if (p.family == "vdbdag lod") continue;  // the lossless bytes again; their cost shows in PSNR/SSIM, in the table
        auto [it, added] = seriesOf.emplace(p.family, series.size());
        if (added) series.push_back({p.family, {}, {}, familyColour(p.family)});
        auto& s = series[it->second];
        where[i] = {it->second, s.x.size()};
        s.x.push_back(byTime ? p.decode.medianMs : double(p.bytes));
        s.y.push_back(p.exact ? 0.0 : p.maxError);
    }
    bridge::PlotSpec spec;
    spec.title = fmt::format("{} - {} against {}", grid, metric == bench::kValueError ? "max error" : metric, byTime ? "decode time" : "size");
    spec.xLabel = byTime ? "decode time (ms, median)" : "size (bytes)";
    spec.yLabel = errorLabel(metric);
    for (size_t i : frontOf(run, ids, byTime))
        if (where.count(i)) spec.front.push_back(where[i]);
    bridge::writeScatterPlot(path, series, spec);
}

} // namespace

nlohmann::json benchToJson(const BenchRun& run) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : run.points)
        points.push_back({{"grid", p.grid},
                          {"tool", p.tool},
                          {"setting", p.setting},
                          {"family", p.family},
                          {"bytes", p.bytes},
                          {"traceable_bytes", p.traceableBytes},
                          {"active_voxels", p.activeVoxels},
                          {"bits_per_voxel", p.bitsPerVoxel()},
                          {"rate_vs_raw", p.rate()},
                          {"metric", p.metric},
                          {"exact", p.exact},
                          {"max_error", p.maxError},
                          {"rms_error", numberOrNull(p.rmsError)},
                          {"mean_error", numberOrNull(p.meanError)},
                          {"render_psnr_db", numberOrNull(p.psnr)},
                          {"render_ssim", numberOrNull(p.ssim)},
                          {"encode", timingJson(p.encode)},
                          {"decode", timingJson(p.decode)},
                          {"trace", timingJson(p.trace)},
                          {"rays_per_second", numberOrNull(p.raysPerSecond)},
                          {"note", p.note}});
    nlohmann::json report{{"input", run.input},   {"sweep", run.sweep},     {"repeats", run.repeats}, {"time_budget_s", run.budgetSeconds}, {"render_width", run.renderWidth},
            {"render_height", run.renderHeight}, {"seconds", run.seconds}, {"machine", run.machine}, {"points", points}};
    addVersions(report);
    return report;
}

void writeBenchReport(const BenchRun& run, const std::string& directory) {
    namespace fs = std::filesystem;
    fs::create_directories(directory);
    const fs::path dir(directory);
    const std::string json = benchToJson(run).dump(2) + "\n";
    writeFileAtomically((dir / "report.json").string(), std::vector<uint8_t>(json.begin(), json.end()));

    std::string csv =
        "grid,tool,setting,bytes,traceable_bytes,active_voxels,bits_per_voxel,rate_vs_raw,metric,exact,max_error,rms_error,mean_error,render_psnr_db,render_ssim,"
        "encode_ms,encode_min_ms,encode_max_ms,decode_ms,decode_min_ms,decode_max_ms,trace_ms,rays_per_second\n";
    auto num = [](double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : std::string(); };
    for (const auto& p : run.points)
        csv += fmt::format("\"{}\",{},\"{}\",{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", p.grid, p.tool, p.setting, p.bytes,
                           p.traceableBytes, p.activeVoxels, num(p.bitsPerVoxel()), num(p.rate()), p.metric, p.exact ? 1 : 0, num(p.maxError),
                           num(p.rmsError), num(p.meanError), num(p.psnr),
                           num(p.ssim), num(p.encode.medianMs), num(p.encode.minMs), num(p.encode.maxMs), num(p.decode.medianMs),
                           num(p.decode.minMs), num(p.decode.maxMs), num(p.trace.medianMs), num(p.raysPerSecond));
    writeFileAtomically((dir / "report.csv").string(), std::vector<uint8_t>(csv.begin(), csv.end()));

    std::string md = fmt::format("# vdbdag bench: {}\n\nSweep `{}`, timings are the median of up to {} run(s) with [min–max] "
                                 "(no further run once a measurement has taken {:g} s; a time without a range is a single run); "
                                 "renders {}x{} on the CPU tracer; {:.0f} s in all. Machine: {}.\n\n",
                                 run.input, run.sweep, run.repeats, run.budgetSeconds, run.renderWidth, run.renderHeight, run.seconds, run.machine);
    md += "Errors are over the active voxels against the input, in the row's metric: `value` = the grid's values (max and RMS absolute; "
          "vec3: the largest component), `colour dE94` = CIELAB ΔE94 of the quantised colours (max and mean), `normal angle deg` = the "
          "angle between the stored ONV normal and the exact gradient normal (max and mean; the values stay exact). "
          "PSNR/SSIM compare the setting's render with the lossless full-resolution render. "
          "P = on the Pareto front of (size, max error); T = on the front of (decode time, max error); fronts are taken within one metric, "
          "the lossless point counting as error 0 for colours (normal rows are compared among themselves).\n\n";
    for (const std::string& grid : gridsOf(run)) {
        const std::vector<size_t> ids = pointsOf(run, grid);
        const std::vector<std::string> metrics = metricsOf(run, ids);
        std::set<size_t> sizeFront, timeFront;
        for (const std::string& metric : metrics) {
            const std::vector<size_t> same = comparable(run, ids, metric);
            for (size_t i : frontOf(run, same, false))
                if (run.points[i].metric == metric) sizeFront.insert(i);
            for (size_t i : frontOf(run, same, true))
                if (run.points[i].metric == metric) timeFront.insert(i);
        }
        md += fmt::format("## Grid `{}`\n\n", grid);
        md += "| tool | setting | bytes | bits/voxel | rate | metric | max error | RMS / mean error | PSNR dB | SSIM | encode ms | decode ms | trace Mrays/s | front |\n";
        md += "|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n";
        for (size_t i : ids) {
            const auto& p = run.points[i];
            const std::string spread = std::isfinite(p.rmsError) ? fmtError(p, p.rmsError) : fmtError(p, p.meanError) + " (mean)";
            md += fmt::format("| {} | {} | {} | {:.2f} | {:.3f} | {} | {} | {} | {} | {} | {} | {} | {} | {}{} |\n", p.tool, p.setting, p.bytes,
                              p.bitsPerVoxel(), p.rate(), p.metric, fmtError(p, p.maxError), spread, fmtOptional(p.psnr, "{:.1f}"),
                              fmtOptional(p.ssim, "{:.4f}"), fmtTiming(p.encode), fmtTiming(p.decode),
                              fmtOptional(p.raysPerSecond / 1e6, "{:.2f}"), sizeFront.count(i) ? "P" : "", timeFront.count(i) ? "T" : "");
        }
        // Where vdbdag is not on the size front, say what beats it.
        std::string offFront;
        for (const std::string& metric : metrics) {
            const std::vector<size_t> same = comparable(run, ids, metric);
            for (size_t i : same) {
                const auto& p = run.points[i];
                if (p.tool != "vdbdag" || p.family == "vdbdag lod" || p.metric != metric || sizeFront.count(i)) continue;
                const double pe = p.exact ? 0.0 : p.maxError;
                for (size_t j : same) {
                    const auto& q = run.points[j];
                    const double qe = q.exact ? 0.0 : q.maxError;
                    if (q.family == "vdbdag lod" || !(q.bytes <= p.bytes && qe <= pe && (q.bytes < p.bytes || qe < pe))) continue;
                    offFront += fmt::format("- {} `{}` ({} B, {} {}) is dominated by {} `{}` ({} B, {}){}\n", p.tool, p.setting, p.bytes,
                                            fmtError(p, p.maxError), metric, q.tool, q.setting, q.bytes, fmtError(q, q.maxError),
                                            q.tool == "vdbdag" ? "" : " - a peer beats vdbdag here");
                    break;
                }
            }
        }
        if (!offFront.empty()) md += "\nvdbdag points off the (size, max error) front:\n\n" + offFront;
        // Matched comparisons: vdbdag encoded with the peer's measured max error as its bound.
        std::string matched;
        for (size_t k : ids) {
            const auto& ours = run.points[k];
            if (ours.family != "vdbdag matched") continue;
            for (size_t i : ids) {
                const auto& peer = run.points[i];
                if (ours.note != "matched to " + peer.tool + " " + peer.setting) continue;
                const bool smaller = ours.bytes < peer.bytes, noWorse = ours.maxError <= peer.maxError;
                matched += fmt::format("| {} {} | {} | {} | {:.3f} | {:.3g} | {:.3g} | {} |\n", peer.tool, peer.setting, peer.bytes, ours.bytes,
                                       double(ours.bytes) / double(std::max<uint64_t>(1, peer.bytes)), peer.maxError, ours.maxError,
                                       smaller && noWorse ? "vdbdag smaller at no larger error"
                                                          : (noWorse ? "vdbdag NOT smaller" : "vdbdag error larger"));
            }
        }
        if (!matched.empty()) {
            md += "\nAt matched error (vdbdag encoded with `--abs-error` = the peer's measured max error):\n\n| peer | peer bytes | vdbdag bytes | ratio | peer max error | vdbdag max error | verdict |\n"
                  "|---|---:|---:|---:|---:|---:|---|\n" +
                  matched;
        }
        md += "\n";
        for (const std::string& metric : metrics) {
            const std::string stem = fileSafe(grid) + (metric == bench::kValueError ? "" : "_" + fileSafe(metric));
            const std::string sizePlot = "error_vs_size_" + stem + ".png", timePlot = "error_vs_time_" + stem + ".png";
            const std::vector<size_t> same = comparable(run, ids, metric);
            plot(run, same, false, (dir / sizePlot).string(), grid, metric);
            plot(run, same, true, (dir / timePlot).string(), grid, metric);
            md += fmt::format("![{} against size]({})\n![{} against decode time]({})\n", metric, sizePlot, metric, timePlot);
        }
        md += "\n";
    }
    writeFileAtomically((dir / "report.md").string(), std::vector<uint8_t>(md.begin(), md.end()));
}

} // namespace vdbdag::app
