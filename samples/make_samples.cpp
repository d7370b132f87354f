// vdbdag_make_samples OUTDIR [--large]
// Writes the sample volumes the demo and the tests use, made with OpenVDB's
// own tools (see samples/README.md for what each one exercises).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetPlatonic.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

namespace {

void write(const std::filesystem::path& path, const openvdb::GridPtrVec& grids) {
    const auto tmp = path.string() + ".tmp";
    openvdb::io::File file(tmp);
    file.write(grids);
    file.close();
    std::filesystem::rename(tmp, path);
    uint64_t voxels = 0;
    for (const auto& g : grids) voxels += g->activeVoxelCount();
    std::printf("%s: %zu grid(s), %llu active voxels\n", path.c_str(), grids.size(), (unsigned long long)voxels);
}

// A torus (major radius R, minor radius r, in voxels) tilted by 30 degrees
// about x, as a triangle mesh turned into a level set by OpenVDB.
openvdb::FloatGrid::Ptr tiltedTorus(float R, float r, float halfWidth) {
    const int nu = 160, nv = 48;
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec4I> quads;
    const double tilt = M_PI / 6.0;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
            const double x = (R + r * std::cos(v)) * std::cos(u), y = (R + r * std::cos(v)) * std::sin(u), z = r * std::sin(v);
            points.emplace_back(float(x), float(y * std::cos(tilt) - z * std::sin(tilt)), float(y * std::sin(tilt) + z * std::cos(tilt)));
        }
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
            quads.emplace_back(i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1);
        }
    auto transform = openvdb::math::Transform::createLinearTransform(1.0);
    return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*transform, points, quads, halfWidth);
}

} // namespace

int main(int argc, char** argv) {
    const bool asked = argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h");
    // No folder, an option where the folder belongs, or an unknown option: the usage, nothing made.
    if (argc < 2 || argc > 3 || argv[1][0] == '-' || (argc == 3 && std::string(argv[2]) != "--large")) {
        std::fprintf(asked ? stdout : stderr, "usage: vdbdag_make_samples OUTDIR [--large]\n");
        return asked ? 0 : 2;
    }
    const std::filesystem::path out = argv[1];
    const bool large = argc == 3;
    std::filesystem::create_directories(out);
    openvdb::initialize();

    // Level-set sphere, radius 40 voxels, half width 3.
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(40.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    sphere->setName("sphere");
    write(out / "sphere_ls.vdb", {sphere});

    // Tilted torus: the demo's sample.
    auto torus = tiltedTorus(48.0f, 16.0f, 3.0f);
    torus->setName("torus");
    torus->setGridClass(openvdb::GRID_LEVEL_SET);
    write(out / "torus_ls.vdb", {torus});

    // Dodecahedron: flat faces.
    auto platonic = openvdb::tools::createLevelSetPlatonic<openvdb::FloatGrid>(12, 60.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    platonic->setName("dodecahedron");
    write(out / "platonic_ls.vdb", {platonic});

    // Fog volume with active tiles inside (sdfToFogVolume of a large sphere).
    auto fog = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(150.0f, openvdb::Vec3f(3.0f, -5.0f, 7.0f), 1.0f, 3.0f);
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("density");
    write(out / "fog_tiles.vdb", {fog});

    // Far-apart and negative coordinates, single voxels at the int32 extremes.
    auto far = openvdb::FloatGrid::create(0.0f);
    far->setName("far_apart");
    {
        auto acc = far->getAccessor();
        const int lo = std::numeric_limits<int32_t>::min(), hi = std::numeric_limits<int32_t>::max();
        for (int x : {lo, hi})
            for (int y : {lo, hi})
                for (int z : {lo, hi}) acc.setValueOn(openvdb::Coord(x, y, z), 1.0f);
        for (int i = 0; i < 200; ++i) {
            acc.setValueOn(openvdb::Coord(-1000000 + i % 17, -5 - i / 17, 3 * i), float(i));
            acc.setValueOn(openvdb::Coord(700000 + i, 12345, -700000 + (i * 7) % 31), float(-i));
        }
        far->tree().addTile(1, openvdb::Coord(-8 * 1000, 0, 8 * 1000), 2.0f, true);  // one 8^3 active tile
    }
    write(out / "far_apart.vdb", {far});

    // Several grids of different types on one topology, one with an empty name.
    auto colour = openvdb::Vec3SGrid::create();
    colour->setName("Cd");
    auto index = openvdb::Int32Grid::create();
    index->setName("");
    auto surface = openvdb::BoolGrid::create();
    surface->setName("surface");
    surface->insertMeta("note", openvdb::StringMetadata("bool grid sharing the sphere's topology"));
    {
        auto c = colour->getAccessor();
        auto n = index->getAccessor();
        auto s = surface->getAccessor();
        int k = 0;
        for (auto it = sphere->cbeginValueOn(); it; ++it, ++k) {
            const openvdb::Coord p = it.getCoord();
            c.setValue(p, openvdb::Vec3s(float(p.x() + 40) / 80.0f, float(p.y() + 40) / 80.0f, float(p.z() + 40) / 80.0f));
            n.setValue(p, k);
            if (*it < 0) s.setValue(p, true);
        }
    }
    write(out / "multi_grid.vdb", {colour, index, surface});

    if (large) {
        // The equivalent of `vdb_tool -sphere d=1024 r=1.0 w=3` (19.5M voxels).
        auto big = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 2.0f / 1024.0f, 3.0f);
        big->setName("sphere");
        write(out / "sphere_d1024_ls.vdb", {big});
    }
    return 0;
}
