// Maximum intensity projection (src/trace/Projection.h, `render --shading
// mip`) against a brute force: every voxel of a dense block as a world-space
// box (OpenVDB's voxel-centred convention: index i covers [i - 0.5, i + 0.5]
// times the voxel size), each pixel's ray tested against all of them by the
// slab method, the largest value of the boxes it crosses.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <OpenImageIO/imageio.h>
#include <openvdb/openvdb.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "src/pipeline/GridCodec.h"
#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/IsoSurface.h"
#include "src/trace/LabelRender.h"
#include "src/trace/Legend.h"
#include "src/trace/Projection.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/SliceView.h"
#include "src/trace/VolumeRender.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

constexpr double kVoxel = 0.5;
constexpr int kNx = 12, kNy = 10, kNz = 8;

// Whether the ray crosses the box (slab method), and where it enters it.
bool crosses(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& lo, const glm::dvec3& hi, double* entry = nullptr) {
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    if (entry) *entry = t0;
    return t1 > t0;
}

// Every voxel of the 12x10x8 block (voxel 0.5) the world ray crosses, with
// where it enters and leaves, in order of entry: the brute force.
struct Crossing {
    double t0, t1;
    int x, y, z;
};
std::vector<Crossing> crossedVoxels(const glm::dvec3& o, const glm::dvec3& d) {
    std::vector<Crossing> out;
    for (int z = 0; z < kNz; ++z)
        for (int y = 0; y < kNy; ++y)
            for (int x = 0; x < kNx; ++x) {
                const glm::dvec3 lo = glm::dvec3(x - 0.5, y - 0.5, z - 0.5) * kVoxel, hi = glm::dvec3(x + 0.5, y + 0.5, z + 0.5) * kVoxel;
                double t0 = 0;
                if (!crosses(o, d, lo, hi, &t0)) continue;
                double t1 = std::numeric_limits<double>::infinity();  // the exit
                for (int a = 0; a < 3; ++a)
                    if (d[a] != 0) t1 = std::min(t1, std::max((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]));
                out.push_back({t0, t1, x, y, z});
            }
    std::stable_sort(out.begin(), out.end(), [](const Crossing& a, const Crossing& b) { return a.t0 < b.t0; });  // ties: z, y, x order
    return out;
}

// The first voxel along the ray that `meets` accepts, if any.
template <typename Meets>
std::optional<Crossing> firstCrossed(const glm::dvec3& o, const glm::dvec3& d, Meets&& meets) {
    for (const Crossing& c : crossedVoxels(o, d))
        if (meets(c)) return c;
    return std::nullopt;
}

// A 12x10x8 int32 block (voxel 0.5) of the values `value(x, y, z)`,
// imported through OpenVDB and encoded.
template <typename Value>
format::EncodedGrid denseBlock(Value&& value) {
    openvdb::initialize();
    auto grid = openvdb::Int32Grid::create(0);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(kVoxel));
    grid->setName("block");
    auto acc = grid->getAccessor();
    for (int z = 0; z < kNz; ++z)
        for (int y = 0; y < kNy; ++y)
            for (int x = 0; x < kNx; ++x) acc.setValueOn(openvdb::Coord(x, y, z), value(x, y, z));
    const fs::path path = fs::temp_directory_path() / ("vdbdag_block_" + std::to_string(::getpid()) + ".vdb");
    {
        openvdb::io::File file(path.string());
        file.write({grid});
    }
    const GridRecord record = bridge::importVdb(path.string(), {}).volume.grids.at(0);
    fs::remove(path);
    return pipeline::encodeGrid(record);
}

trace::Camera obliqueCamera() {
    trace::Camera camera;
    camera.width = 40, camera.height = 30;
    camera.eye = {9.3, 7.1, -6.4};
    camera.target = {2.8, 2.3, 1.9};
    camera.up = {0.1, 1.0, 0.05};
    camera.fovDegrees = 50;
    return camera;
}

} // namespace

TEST(Projection, MaximaEqualABruteForceOverTheDenseBlock) {
    std::mt19937 rng(9);
    std::vector<int32_t> values(size_t(kNx) * kNy * kNz);
    for (int32_t& v : values) v = int32_t(rng() % 2000) - 1000;
    const format::EncodedGrid encoded = denseBlock([&](int x, int y, int z) { return values[size_t((z * kNy + y) * kNx + x)]; });
    const trace::RenderGrid render = trace::makeRenderGrid(encoded, trace::Shading::Mip);
    ASSERT_TRUE(render.mip);
    const trace::Camera camera = obliqueCamera();
    const std::vector<double> maxima = trace::maximaAlongRays(render, camera);
    size_t met = 0, differ = 0;
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) {
            glm::dvec3 o, d;
            camera.pixelRay(px, py, o, d);
            double best = -std::numeric_limits<double>::infinity();
            for (int z = 0; z < kNz; ++z)
                for (int y = 0; y < kNy; ++y)
                    for (int x = 0; x < kNx; ++x) {
                        const glm::dvec3 lo = glm::dvec3(x - 0.5, y - 0.5, z - 0.5) * kVoxel, hi = glm::dvec3(x + 0.5, y + 0.5, z + 0.5) * kVoxel;
                        if (crosses(o, d, lo, hi)) best = std::max(best, double(values[size_t((z * kNy + y) * kNx + x)]));
                    }
            const double got = maxima[size_t(py) * size_t(camera.width) + size_t(px)];
            if (std::isinf(best)) {
                EXPECT_TRUE(std::isnan(got)) << px << "," << py << ": " << got;
                continue;
            }
            ++met;
            differ += got != best;
        }
    EXPECT_GT(met, size_t(camera.width * camera.height / 4));
    EXPECT_EQ(differ, 0u) << "of " << met << " pixels that meet the block";
    // The image: transparent at or below the window's low end, grey above.
    const trace::Projection p = trace::renderMip(render, camera, std::pair{0.0, 1000.0});
    for (size_t i = 0; i < maxima.size(); ++i) EXPECT_EQ(p.image.alpha[i] > 0, maxima[i] > 0.0) << i;
}

// The automatic window of a two-level picture (air and tissue): its low end
// lies between the two (Otsu), so the air is transparent.
TEST(Projection, TheAutomaticWindowSeparatesAirFromTissue) {
    std::vector<double> maxima(1000, -1000.0);
    for (size_t i = 0; i < 300; ++i) maxima[i] = 40.0 + double(i % 50);
    maxima.push_back(std::numeric_limits<double>::quiet_NaN());
    const auto [low, high] = trace::automaticWindow(maxima);
    EXPECT_GT(low, -1000.0);
    EXPECT_LT(low, 40.0);
    EXPECT_GE(high, 80.0);
    EXPECT_LE(high, 89.0);
}

// `render` of a dense scan with the default shading (issue 42: a CT
// rendered as an opaque box): a volume whose air is transparent, as the
// maximum intensity projection's is. A 48^3 int16 scan of a ball (1000) in
// air (-1000): the covered pixels (alpha read back by OpenImageIO) are
// those whose ray meets the ball, far fewer than the box's, which
// `--shading values` covers.
TEST(Projection, ADenseScanRendersByDefaultAsAVolumeWithTransparentAir) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_mip_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path raw = dir / "ball_48x48x48_int16le.raw", ss = dir / "ball.ssvdag";
    {
        std::vector<int16_t> samples(48 * 48 * 48);
        for (int z = 0; z < 48; ++z)
            for (int y = 0; y < 48; ++y)
                for (int x = 0; x < 48; ++x) {
                    const double r = std::sqrt((x - 23.5) * (x - 23.5) + (y - 23.5) * (y - 23.5) + (z - 23.5) * (z - 23.5));
                    samples[size_t((z * 48 + y) * 48 + x)] = int16_t(r < 12 ? 1000 : -1000);
                }
        std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(samples.data()), std::streamsize(samples.size() * 2));
    }
    ASSERT_EQ(vdbdag::testing::runCli("encode " + raw.string() + " -o " + ss.string()).exitCode, 0);
    auto covered = [&](const std::string& extra, std::string* err) {
        const fs::path exr = dir / "r.exr";
        const vdbdag::testing::CommandResult r = vdbdag::testing::runCli("render " + ss.string() + " -o " + exr.string() + " -f --width 64 --height 64 " + extra);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        if (err) *err = r.err;
        auto in = OIIO::ImageInput::open(exr.string());
        if (!in) return -1.0;
        std::vector<float> a(64 * 64);
        const int alpha = in->spec().alpha_channel;
        if (alpha < 0 || !in->read_image(0, 0, alpha, alpha + 1, OIIO::TypeDesc::FLOAT, a.data())) return -1.0;
        in->close();
        size_t n = 0;
        for (const float v : a) n += v > 0;
        return double(n) / double(a.size());
    };
    std::string note;
    const double volume = covered("", &note), projected = covered("--shading mip", nullptr), box = covered("--shading values", nullptr);
    EXPECT_NE(note.find("shown as a volume"), std::string::npos) << note;
    EXPECT_NEAR(volume, projected, 0.01) << "the ball's pixels, no more";
    EXPECT_GT(projected, 0.02);
    EXPECT_LE(projected, 0.85 * box) << projected << " of the pixels against the box's " << box;
    // The isosurface of the ball's rim covers what the projection does
    // (the ball, seen whole); --iso applies to --shading iso only.
    EXPECT_NEAR(covered("--shading iso --iso 0", nullptr), projected, 0.01);
    const vdbdag::testing::CommandResult json = vdbdag::testing::runCli("render " + ss.string() + " -o " + (dir / "i.png").string() +
                                                                        " -f --width 32 --height 32 --shading iso --json");
    ASSERT_EQ(json.exitCode, 0) << json.err;
    const double chosen = nlohmann::json::parse(json.out).at("iso").get<double>();
    EXPECT_GT(chosen, -1000.0);
    EXPECT_LT(chosen, 1000.0);
    const vdbdag::testing::CommandResult refused = vdbdag::testing::runCli("render " + ss.string() + " -o " + (dir / "j.png").string() + " --iso 5");
    EXPECT_NE(refused.exitCode, 0);
    EXPECT_NE(refused.err.find("--iso applies to --shading iso"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(dir / "j.png"));
    fs::remove_all(dir);
}

// A scan in patient space is shown head up from the front (issue 42 #3): a
// NRRD in LPS (x left, y posterior, z superior) renders by default with the
// image's up along +z and the eye on the anterior side (y below the
// target's); --up/--view still choose.
TEST(Projection, AScanInPatientSpaceIsShownHeadUpFromTheFront) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_lps_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path nrrd = dir / "head.nrrd", ss = dir / "head.ssvdag";
    {
        std::ofstream f(nrrd, std::ios::binary);
        f << "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 20 24 28\n"
             "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: raw\n\n";
        std::vector<int16_t> samples(20 * 24 * 28);
        for (size_t i = 0; i < samples.size(); ++i) samples[i] = int16_t(i % 97 < 40 ? -1000 : 500);
        f.write(reinterpret_cast<const char*>(samples.data()), std::streamsize(samples.size() * 2));
    }
    ASSERT_EQ(vdbdag::testing::runCli("encode " + nrrd.string() + " -o " + ss.string()).exitCode, 0);
    const fs::path png = dir / "r.png";
    vdbdag::testing::CommandResult r = vdbdag::testing::runCli("render " + ss.string() + " -o " + png.string() + " -f --width 16 --height 16 --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    nlohmann::json camera = nlohmann::json::parse(r.out)["camera"];
    EXPECT_EQ(camera["up"], nlohmann::json({0.0, 0.0, 1.0})) << camera.dump();
    EXPECT_LT(camera["eye"][1].get<double>(), camera["target"][1].get<double>()) << camera.dump();
    EXPECT_NE(r.err.find("head up"), std::string::npos) << r.err;
    r = vdbdag::testing::runCli("render " + ss.string() + " -o " + png.string() + " -f --width 16 --height 16 --json --up y");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    camera = nlohmann::json::parse(r.out)["camera"];
    EXPECT_NE(camera["up"], nlohmann::json({0.0, 0.0, 1.0})) << camera.dump();
    fs::remove_all(dir);
}

// Labels (src/trace/LabelRender.h, `--shading labels`) against a brute
// force: each pixel's label is that of the shown voxel its ray enters first
// (every box tested by the slab method), for all labels but 0 and for a
// chosen few; distinct labels get distinct colours.
TEST(LabelRender, FirstLabelsEqualABruteForceOverTheDenseBlock) {
    const auto labelAt = [](int x, int y, int z) -> int32_t {
        if (x >= 2 && x < 6 && y >= 1 && y < 5 && z >= 1 && z < 4) return 3;
        if (x >= 5 && x < 10 && y >= 4 && y < 9 && z >= 3 && z < 7) return 17;
        if ((x + y + z) % 7 == 0) return 5;
        return 0;
    };
    const format::EncodedGrid encoded = denseBlock(labelAt);
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded, trace::Shading::Labels);
    ASSERT_TRUE(grid.labels);
    const trace::Camera camera = obliqueCamera();
    for (const std::vector<int64_t>& shown : {std::vector<int64_t>{}, std::vector<int64_t>{17}, std::vector<int64_t>{3, 5}}) {
        const std::vector<std::optional<trace::LabelHit>> hits = trace::firstLabels(grid, camera, shown);
        size_t met = 0, differ = 0;
        for (int py = 0; py < camera.height; ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 o, d;
                camera.pixelRay(px, py, o, d);
                const std::optional<Crossing> want = firstCrossed(o, d, [&](const Crossing& c) {
                    const int32_t l = labelAt(c.x, c.y, c.z);
                    return shown.empty() ? l != 0 : std::find(shown.begin(), shown.end(), int64_t(l)) != shown.end();
                });
                const auto& got = hits[size_t(py) * size_t(camera.width) + size_t(px)];
                if (!want) {
                    EXPECT_FALSE(got.has_value()) << px << "," << py;
                    continue;
                }
                ++met;
                differ += !got || got->label != labelAt(want->x, want->y, want->z);
            }
        EXPECT_GT(met, 20u) << shown.size();
        EXPECT_EQ(differ, 0u) << "of " << met << " pixels, " << shown.size() << " labels chosen";
    }
    EXPECT_NE(trace::labelColour(3), trace::labelColour(5));
    EXPECT_NE(trace::labelColour(5), trace::labelColour(17));
    EXPECT_EQ(trace::labelColour(17), trace::labelColour(17));
}


// Isosurfaces (src/trace/IsoSurface.h, `--shading iso`) against a brute
// force over 10^4 rays: each pixel's hit is the voxel reaching the value
// that its ray enters first (every box tested by the slab method), at two
// values; the image is lit where the brute force meets one.
TEST(IsoSurface, FirstCrossingsEqualABruteForceOverTheDenseBlock) {
    const auto valueAt = [](int x, int y, int z) -> int32_t {
        const double r = std::sqrt((x - 5.5) * (x - 5.5) + (y - 4.5) * (y - 4.5) + (z - 3.5) * (z - 3.5));
        return int32_t(std::lround(1000 - 180 * r + 37 * ((x * 7 + y * 3 + z * 5) % 4)));
    };
    const format::EncodedGrid encoded = denseBlock(valueAt);
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded, trace::Shading::Iso);
    ASSERT_TRUE(grid.iso);
    trace::Camera camera = obliqueCamera();
    camera.width = 100, camera.height = 100;
    for (const double iso : {400.0, 733.5}) {
        const std::vector<std::optional<trace::IsoHit>> hits = trace::firstCrossings(grid, camera, iso);
        size_t met = 0, differ = 0;
        for (int py = 0; py < camera.height; ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 o, d;
                camera.pixelRay(px, py, o, d);
                const std::optional<Crossing> want = firstCrossed(o, d, [&](const Crossing& c) { return valueAt(c.x, c.y, c.z) >= iso; });
                const auto& got = hits[size_t(py) * size_t(camera.width) + size_t(px)];
                if (!want) {
                    EXPECT_FALSE(got.has_value()) << px << "," << py;
                    continue;
                }
                ++met;
                differ += !got || got->box.voxel != std::array<int64_t, 3>{want->x, want->y, want->z};
                if (got) { EXPECT_GE(valueAt(int(got->box.voxel[0]), int(got->box.voxel[1]), int(got->box.voxel[2])), iso); }
            }
        EXPECT_GT(met, 200u) << iso;
        EXPECT_EQ(differ, 0u) << "of " << met << " pixels, iso " << iso;
        trace::RenderOptions options;
        const trace::Image image = trace::renderIso(grid, camera, options, iso);
        for (size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(image.alpha[i] > 0, hits[i].has_value()) << i;
    }
    // The default value parts the low values from the high ones.
    const double automatic = trace::automaticIso(grid);
    EXPECT_GT(automatic, double(valueAt(0, 0, 0)));
    EXPECT_LT(automatic, double(valueAt(5, 4, 3)));
}

// Volume rendering (src/trace/VolumeRender.h, `--shading volume`) against a
// brute force: each pixel's ray against every voxel of the dense block (slab
// method), the boxes it crosses composited front to back in order of entry
// through the same transfer function, lit by a central-difference gradient
// of the dense array itself (not of the DAG's lookups), with the renderer's
// thresholds (light above 0.01 of opacity, stop under 0.02 transmittance).
TEST(VolumeRender, CompositingEqualsABruteForceOverTheDenseBlock) {
    const auto valueAt = [](int x, int y, int z) -> int32_t {
        const double r = std::sqrt((x - 5.5) * (x - 5.5) + (y - 4.5) * (y - 4.5) + (z - 3.5) * (z - 3.5));
        return int32_t(std::lround(900 - 150 * r + 29 * ((x * 5 + y * 3 + z * 7) % 5)));
    };
    const format::EncodedGrid encoded = denseBlock(valueAt);
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded, trace::Shading::Volume);
    ASSERT_TRUE(grid.volume);
    const trace::Camera camera = obliqueCamera();
    // The default ramp over a window, and points read from a ParaView preset
    // (a --tf file: colour points in sRGB, an opacity ramp with a plateau).
    const fs::path presetPath = fs::temp_directory_path() / ("vdbdag_tf_" + std::to_string(::getpid()) + ".json");
    std::ofstream(presetPath) << R"([{"Name": "test", "RGBPoints": [150, 0.1, 0.2, 0.9, 500, 1, 0.5, 0, 950, 1, 1, 1],
                                       "Points": [250, 0, 0.5, 0, 600, 0.8, 0.5, 0, 800, 0.8, 0.5, 0, 1000, 1, 0.5, 0]}])";
    const trace::TransferFunction fromFile = trace::readTransferFunction(presetPath.string());
    fs::remove(presetPath);
    for (const trace::TransferFunction& tf : {trace::TransferFunction{200, 900, {}, {}}, fromFile}) {
        trace::RenderOptions options;
        const trace::Image image = trace::renderVolume(grid, camera, options, tf);
        const glm::dvec3 light = trace::defaultLight(camera.eye, camera.target, camera.up);
        const auto stored = [&](int x, int y, int z) { return x >= 0 && y >= 0 && z >= 0 && x < kNx && y < kNy && z < kNz; };
        size_t met = 0;
        double worst = 0;
        for (int py = 0; py < camera.height; ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 o, d;
                camera.pixelRay(px, py, o, d);
                const std::vector<Crossing> crossings = crossedVoxels(o, d);
                double transmittance = 1;
                glm::dvec3 sum(0);
                for (const Crossing& c : crossings) {
                    const double v = valueAt(c.x, c.y, c.z), a = tf.opacity(v);
                    if (a <= 0) continue;
                    const double alpha = 1 - std::pow(1 - a, (c.t1 - c.t0) * glm::length(d) / kVoxel);
                    if (!(alpha > 0)) continue;
                    double lit = 1;
                    if (alpha > 0.01) {
                        glm::dvec3 g(0);
                        for (int k = 0; k < 3; ++k) {
                            int p[3] = {c.x, c.y, c.z}, m[3] = {c.x, c.y, c.z};
                            ++p[k], --m[k];
                            const bool hp = stored(p[0], p[1], p[2]), hm = stored(m[0], m[1], m[2]);
                            if (hp && hm) g[k] = (valueAt(p[0], p[1], p[2]) - valueAt(m[0], m[1], m[2])) * 0.5;
                            else if (hp) g[k] = valueAt(p[0], p[1], p[2]) - v;
                            else if (hm) g[k] = v - valueAt(m[0], m[1], m[2]);
                        }
                        if (glm::length(g) > 0) {
                            glm::dvec3 n = glm::normalize(-g);
                            if (glm::dot(n, d) > 0) n = -n;
                            lit = trace::kAmbient + (1 - trace::kAmbient) * std::max(0.0, glm::dot(n, light));
                        }
                    }
                    sum += transmittance * alpha * lit * tf.colour(v);
                    transmittance *= 1 - alpha;
                    if (transmittance < 0.02) break;
                }
                const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
                EXPECT_NEAR(image.alpha[i], 1 - transmittance, 1e-5) << px << "," << py;
                const glm::dvec3 want = sum + transmittance * options.background;
                for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(double(image.rgb[3 * i + size_t(a)]) - want[a]));
                met += transmittance < 1;
            }
        EXPECT_GT(met, 100u);
        EXPECT_LT(worst, 1e-5) << "largest colour difference over " << met << " covered pixels";
    }
}

// A --tf file (a ParaView colour-map preset) against its closed form: colours
// from sRGB to linear, linear between points and clamped beyond; opacity
// points scaled by kMaxOpacity; without "Points" the ramp over the colour
// points' range; bad files refused naming the file.
TEST(VolumeRender, ATransferFunctionFileIsReadAsParaViewWritesIt) {
    const fs::path path = fs::temp_directory_path() / ("vdbdag_tf_read_" + std::to_string(::getpid()) + ".json");
    const auto write = [&](const std::string& text) { std::ofstream(path) << text; };
    const auto linear = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
    write(R"({"RGBPoints": [0, 0, 0.5, 1, 10, 1, 0.5, 0], "Points": [2, 0, 0.5, 0, 6, 1, 0.5, 0]})");
    trace::TransferFunction tf = trace::readTransferFunction(path.string());
    EXPECT_EQ(tf.low, 0);
    EXPECT_EQ(tf.high, 10);
    const glm::dvec3 mid = tf.colour(5);
    EXPECT_NEAR(mid.r, 0.5 * linear(1.0), 1e-12);
    EXPECT_NEAR(mid.g, linear(0.5), 1e-12);
    EXPECT_NEAR(mid.b, 0.5 * linear(1.0), 1e-12);
    EXPECT_NEAR(tf.colour(-3).b, 1.0, 1e-12) << "clamped below";
    EXPECT_NEAR(tf.opacity(4), 0.5 * trace::kMaxOpacity, 1e-12);
    EXPECT_EQ(tf.opacity(1), 0);
    EXPECT_NEAR(tf.opacity(100), trace::kMaxOpacity, 1e-12);
    write(R"({"RGBPoints": [100, 0, 0, 0, 300, 1, 1, 1]})");
    tf = trace::readTransferFunction(path.string());
    EXPECT_EQ(tf.opacity(100), 0);
    EXPECT_NEAR(tf.opacity(200), trace::kMaxOpacity * 0.25, 1e-12) << "the ramp over the points' range";
    for (const char* bad : {"{}", "[1, 2", R"({"RGBPoints": [0, 0, 0, 0]})", R"({"RGBPoints": [5, 0, 0, 0, 1, 1, 1, 1]})",
                            R"({"RGBPoints": [0, 0, 0, 0, 1, 1, 1]})", R"({"RGBPoints": [0, 0, 0, 0, 1, 1, 1, "x"]})"}) {
        write(bad);
        try {
            trace::readTransferFunction(path.string());
            ADD_FAILURE() << "accepted " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
        }
    }
    fs::remove(path);
    EXPECT_THROW(trace::readTransferFunction(path.string()), Error);
}

// The default shading of a dense scan in bytes: an 8-bit scan (a ball of
// noisy tissue in air, at most 256 values with 0 among them) is a volume;
// a label volume of the same type and shape (three regions) is labels.
TEST(Projection, AnEightBitScanIsAVolumeAndALabelVolumeIsLabelsByDefault) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_u8_default_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::mt19937 rng(4);
    const auto shadingOf = [&](const std::string& name, auto&& sample) {
        const fs::path raw = dir / (name + "_40x40x40_uint8.raw");
        std::vector<uint8_t> samples(40 * 40 * 40);
        for (int z = 0; z < 40; ++z)
            for (int y = 0; y < 40; ++y)
                for (int x = 0; x < 40; ++x) samples[size_t((z * 40 + y) * 40 + x)] = sample(x, y, z);
        std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(samples.data()), std::streamsize(samples.size()));
        const vdbdag::testing::CommandResult r =
            vdbdag::testing::runCli("render " + raw.string() + " -o " + (dir / (name + ".png")).string() + " -f --width 16 --height 16 --json");
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return r.exitCode == 0 ? nlohmann::json::parse(r.out).at("shading").get<std::string>() : std::string();
    };
    const auto r = [](int x, int y, int z) { return std::sqrt((x - 19.5) * (x - 19.5) + (y - 19.5) * (y - 19.5) + (z - 19.5) * (z - 19.5)); };
    EXPECT_EQ(shadingOf("scan", [&](int x, int y, int z) { return uint8_t(r(x, y, z) < 15 ? 120 + rng() % 60 : rng() % 3); }), "volume");
    EXPECT_EQ(shadingOf("atlas", [&](int x, int y, int z) { return uint8_t(r(x, y, z) < 8 ? 7 : r(x, y, z) < 15 ? (x < 20 ? 3 : 4) : 0); }), "labels");
    fs::remove_all(dir);
}

// Slices (src/trace/SliceView.h, `--shading slice --slice z=3`) against a
// brute force: each pixel's world ray meets the world plane through the
// centres of the slice's voxels at a point whose nearest voxel centre (the
// voxel-centred convention) gives the value, on each axis; the image is grey
// there and transparent elsewhere; the CLI frames the slice along its axis.
TEST(SliceView, SliceValuesEqualABruteForceOverTheDenseBlock) {
    const auto valueAt = [](int x, int y, int z) -> int32_t { return x * 100 + y * 10 + z; };
    const format::EncodedGrid encoded = denseBlock(valueAt);
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded, trace::Shading::Slice);
    ASSERT_TRUE(grid.slice);
    const trace::Camera camera = obliqueCamera();
    const int dims[3] = {kNx, kNy, kNz};
    for (const trace::SlicePlane plane : {trace::SlicePlane{2, 3}, trace::SlicePlane{0, 7}, trace::SlicePlane{1, 0}}) {
        const std::vector<double> values = trace::sliceValues(grid, camera, plane);
        size_t met = 0, differ = 0;
        for (int py = 0; py < camera.height; ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 o, d;
                camera.pixelRay(px, py, o, d);
                const size_t a = size_t(plane.axis);
                const double t = (double(plane.index) * kVoxel - o[a]) / d[a];
                std::optional<int32_t> want;
                bool edge = false;
                if (t >= 0) {
                    int idx[3];
                    bool inside = true;
                    for (size_t k = 0; k < 3; ++k) {
                        const double c = k == a ? double(plane.index) : (o[k] + t * d[k]) / kVoxel;
                        edge = edge || (k != a && std::abs(c - std::floor(c) - 0.5) < 1e-9);
                        idx[k] = int(std::lround(c));
                        inside = inside && idx[k] >= 0 && idx[k] < dims[k];
                    }
                    if (inside) want = valueAt(idx[0], idx[1], idx[2]);
                }
                if (edge) continue;  // on a voxel boundary: either side is right
                const double got = values[size_t(py) * size_t(camera.width) + size_t(px)];
                if (!want) {
                    EXPECT_TRUE(std::isnan(got)) << px << "," << py << " axis " << plane.axis;
                    continue;
                }
                ++met;
                differ += got != double(*want);
            }
        EXPECT_GT(met, 50u) << "axis " << plane.axis;
        EXPECT_EQ(differ, 0u) << "of " << met << " pixels, axis " << plane.axis;
        const trace::Projection p = trace::renderSlice(grid, camera, plane, std::pair{0.0, 1000.0});
        for (size_t i = 0; i < values.size(); ++i) EXPECT_EQ(p.image.alpha[i] > 0, !std::isnan(values[i])) << i;
    }
    EXPECT_THROW(trace::parseSlicePlane("w=3"), Error);
    EXPECT_THROW(trace::parseSlicePlane("z=3.5"), Error);
    EXPECT_EQ(trace::parseSlicePlane("y=-2").axis, 1);
    EXPECT_EQ(trace::parseSlicePlane("y=-2").index, -2);
}

// The colour bar (src/trace/Legend.h, `render --legend`): down the bar the
// colours are the scale's, from high at the top to low at the bottom (a
// grey window: strictly darker going down), with both numbers drawn above
// and below it; a small image is left alone; the CLI refuses it where no
// one value map applies.
TEST(Legend, TheBarShowsTheScaleFromHighToLowWithItsNumbers) {
    trace::Image image;
    image.resize(320, 240);
    const trace::LegendScale scale{-1000, 3000, [](double v) { return glm::dvec3((v + 1000) / 4000); }, ""};
    trace::drawLegend(image, scale);
    // The bar: the rightmost opaque column run in the middle of the image.
    int column = -1;
    for (int x = image.width - 1; x >= 0 && column < 0; --x)
        if (image.alpha[size_t(image.height / 2) * size_t(image.width) + size_t(x)] > 0) column = x - 1;
    ASSERT_GT(column, image.width / 2);
    std::vector<float> down;
    for (int y = 0; y < image.height; ++y) {
        const size_t i = size_t(y) * size_t(image.width) + size_t(column);
        if (image.alpha[i] > 0 && image.rgb[3 * i] < 1.0f) down.push_back(image.rgb[3 * i]);
    }
    ASSERT_GT(down.size(), size_t(image.height / 2));
    for (size_t k = 1; k < down.size(); ++k) EXPECT_LT(down[k], down[k - 1]) << k;
    EXPECT_NEAR(down.front(), 1.0, 0.02);
    EXPECT_NEAR(down.back(), 0.0, 0.02);
    // Numbers above and below the bar: white pixels in the top and bottom rows of the margin.
    const auto whiteIn = [&](int y0, int y1) {
        size_t n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = image.width / 2; x < image.width; ++x) n += image.rgb[3 * (size_t(y) * size_t(image.width) + size_t(x))] == 1.0f;
        return n;
    };
    EXPECT_GT(whiteIn(0, 12), 10u);
    EXPECT_GT(whiteIn(image.height - 12, image.height), 10u);
    trace::Image small;
    small.resize(40, 30);
    trace::drawLegend(small, scale);
    for (const float a : small.alpha) EXPECT_EQ(a, 0.0f);
    // A level set's surface has no value map: refused.
    const format::EncodedGrid encoded = denseBlock([](int x, int, int) { return x; });
    EXPECT_FALSE(trace::legendScale(trace::makeRenderGrid(encoded, trace::Shading::Iso), std::pair{0.0, 1.0}));
    EXPECT_TRUE(trace::legendScale(trace::makeRenderGrid(encoded, trace::Shading::Mip), std::pair{0.0, 1.0}));
    EXPECT_TRUE(trace::legendScale(trace::makeRenderGrid(encoded, trace::Shading::Values), std::nullopt));
}

// Units after the high value, from the grid's DICOM metadata: a PET's Units,
// a Rescale Type, a CT's HU; nothing when nothing says. Drawn, the label
// reaches further left than the number alone.
TEST(Legend, UnitsComeFromTheMetadataAndFollowTheHighValue) {
    using M = std::vector<std::pair<std::string, std::string>>;
    EXPECT_EQ(trace::valueUnits(M{{"dicom_Modality", "PT"}, {"dicom_Units", "BQML"}}), "Bq/ml");
    EXPECT_EQ(trace::valueUnits(M{{"dicom_Units", "CNTS"}}), "counts");
    EXPECT_EQ(trace::valueUnits(M{{"dicom_Modality", "CT"}, {"dicom_RescaleType", "HU"}}), "HU");
    EXPECT_EQ(trace::valueUnits(M{{"dicom_Modality", "CT"}}), "HU");
    EXPECT_EQ(trace::valueUnits(M{{"dicom_Modality", "MR"}}), "");
    EXPECT_EQ(trace::valueUnits(M{}), "");
    const auto leftmostWhite = [](const trace::Image& image) {
        int left = image.width;
        for (int y = 0; y < 12; ++y)
            for (int x = 0; x < image.width; ++x)
                if (image.rgb[3 * (size_t(y) * size_t(image.width) + size_t(x))] == 1.0f) left = std::min(left, x);
        return left;
    };
    trace::LegendScale scale{0, 1500, [](double v) { return glm::dvec3(v / 1500); }, ""};
    trace::Image plain, withUnits;
    plain.resize(320, 240), withUnits.resize(320, 240);
    trace::drawLegend(plain, scale);
    scale.units = "Bq/ml";
    trace::drawLegend(withUnits, scale);
    EXPECT_LT(leftmostWhite(withUnits), leftmostWhite(plain) - 5 * 4) << "six more glyphs of 4 pixels";
}
