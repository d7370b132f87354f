// vdbdag_make_sequence OUTDIR [--frames N] [--dim D] [--no-fog]
// A real simulation cache made with OpenVDB's own tools, for frame
// sequences (issue 43): a level-set sphere (radius 0.15 at (0.35, 0.35,
// 0.35) in the unit box, voxel size 1/D) advected through the Enright
// vortex field (tools::EnrightField, tools::LevelSetAdvection, the standard
// level-set advection benchmark; period 3) for N frames of 0.05 time units,
// written as OUTDIR/levelset.0001.vdb ... (frame numbers from 1, grid
// "surface", metadata "frame" and "time"), and each frame's fog volume
// (tools::sdfToFogVolume of a copy) as OUTDIR/fog.0001.vdb ... (grid
// "density"). Defaults: 48 frames at D = 256.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetAdvect.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/VelocityFields.h>

namespace {

void write(const std::filesystem::path& path, openvdb::GridBase::Ptr grid) {
    const auto tmp = path.string() + ".tmp";
    openvdb::io::File file(tmp);
    file.write({grid});
    file.close();
    std::filesystem::rename(tmp, path);
}

std::string frameName(const std::string& stem, int frame) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, ".%04d.vdb", frame);
    return stem + buffer;
}

int usage(bool asked = false) {
    std::fprintf(asked ? stdout : stderr, "usage: vdbdag_make_sequence OUTDIR [--frames N (1-9999, 48)] [--dim D (16-4096, 256)] [--no-fog]\n");
    return asked ? 0 : 2;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) return usage();
    // An option where the folder belongs (--help) is not made a folder.
    if (argv[1][0] == '-') return usage(std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h");
    const std::filesystem::path out = argv[1];
    int frames = 48, dim = 256;
    bool fog = true;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
        else if (a == "--dim" && i + 1 < argc) dim = std::atoi(argv[++i]);
        else if (a == "--no-fog") fog = false;
        else return usage();
    }
    if (frames < 1 || frames > 9999 || dim < 16 || dim > 4096) return usage();
    openvdb::initialize();
    std::filesystem::create_directories(out);
    const float voxel = 1.0f / float(dim), halfWidth = 3.0f;
    openvdb::FloatGrid::Ptr surface = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.15f, openvdb::Vec3f(0.35f), voxel, halfWidth);
    surface->setName("surface");
    const openvdb::tools::EnrightField<float> field;
    openvdb::tools::LevelSetAdvection<openvdb::FloatGrid, openvdb::tools::EnrightField<float>> advection(*surface, field);
    advection.setSpatialScheme(openvdb::math::HJWENO5_BIAS);
    advection.setTemporalScheme(openvdb::math::TVD_RK2);
    constexpr float kFrameTime = 0.05f;
    for (int f = 1; f <= frames; ++f) {
        if (f > 1) advection.advect(kFrameTime * float(f - 2), kFrameTime * float(f - 1));
        surface->insertMeta("frame", openvdb::Int32Metadata(f));
        surface->insertMeta("time", openvdb::FloatMetadata(kFrameTime * float(f - 1)));
        write(out / frameName("levelset", f), surface->deepCopy());
        if (fog) {
            openvdb::FloatGrid::Ptr density = surface->deepCopy();
            openvdb::tools::sdfToFogVolume(*density);
            density->setName("density");
            write(out / frameName("fog", f), density);
        }
        std::printf("frame %d of %d: %llu active voxels\n", f, frames, (unsigned long long)surface->activeVoxelCount());
        std::fflush(stdout);
    }
    return 0;
}
