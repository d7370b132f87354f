// The float coders vdbdag's float values are measured against (issue 40's
// peers), on the leaves of a float grid of a .vdb as OpenVDB reads them:
//
//   vdbdag_float_bench FILE.vdb [--grid NAME] [--repeats R]
//
// - fpzip (Lindstrom's lossless predictive coder, Debian libfpzip) of the
//   same leaves, in the better of two arrangements for it: the leaves'
//   8x8x8 buffers stacked into one 8 x 8 x 8N array (inactive voxels hold
//   their background values, as OpenVDB stores them), or the active values
//   alone in leaf order as one line. fpzip is told the values' precision:
//   32 bits less their common zero low bits (19 for a file stored as half
//   floats), which it keeps exactly, so it is not charged for zeros.
// - ZFP in its reversible (lossless) mode on the stacked leaves.
// Every decode is checked bit for bit against the input. Timings: medians
// of R runs, one core. One JSON object on stdout.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <fpzip.h>
#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <zfp.h>

#include "tests/tools/BenchTiming.h"

namespace {

using vdbdag::benchtools::Clock;
using vdbdag::benchtools::median;
using vdbdag::benchtools::seconds;

struct Coded {
    size_t bytes = 0;
    double encodeSeconds = 0, decodeSeconds = 0;
};

// fpzip of `values` as an nx x ny x nz array at `prec` bits, checked.
Coded fpzipOf(const std::vector<float>& values, int nx, int ny, int nz, int prec, int repeats) {
    std::vector<char> buffer(values.size() * 4 + 65536);
    std::vector<double> enc, dec;
    Coded out;
    for (int r = 0; r < repeats; ++r) {
        const auto t0 = Clock::now();
        FPZ* f = fpzip_write_to_buffer(buffer.data(), buffer.size());
        f->type = FPZIP_TYPE_FLOAT, f->prec = prec, f->nx = nx, f->ny = ny, f->nz = nz, f->nf = 1;
        if (!fpzip_write_header(f)) throw std::runtime_error("fpzip header");
        out.bytes = fpzip_write(f, values.data());
        fpzip_write_close(f);
        if (!out.bytes) throw std::runtime_error("fpzip write failed");
        const auto t1 = Clock::now();
        std::vector<float> back(values.size());
        FPZ* g = fpzip_read_from_buffer(buffer.data());
        if (!fpzip_read_header(g) || !fpzip_read(g, back.data())) throw std::runtime_error("fpzip read failed");
        fpzip_read_close(g);
        const auto t2 = Clock::now();
        if (std::memcmp(back.data(), values.data(), values.size() * 4)) throw std::runtime_error("fpzip is not lossless here");
        enc.push_back(seconds(t0, t1)), dec.push_back(seconds(t1, t2));
    }
    out.encodeSeconds = median(enc), out.decodeSeconds = median(dec);
    return out;
}

Coded zfpReversibleOf(std::vector<float> values, size_t leaves, int repeats) {
    std::vector<double> enc, dec;
    Coded out;
    for (int r = 0; r < repeats; ++r) {
        zfp_field* field = zfp_field_3d(values.data(), zfp_type_float, 8, 8, 8 * leaves);
        zfp_stream* zfp = zfp_stream_open(nullptr);
        zfp_stream_set_reversible(zfp);
        std::vector<unsigned char> buffer(zfp_stream_maximum_size(zfp, field));
        bitstream* stream = stream_open(buffer.data(), buffer.size());
        zfp_stream_set_bit_stream(zfp, stream);
        const auto t0 = Clock::now();
        zfp_stream_rewind(zfp);
        out.bytes = zfp_compress(zfp, field);
        const auto t1 = Clock::now();
        std::vector<float> back(values.size());
        zfp_field_set_pointer(field, back.data());
        zfp_stream_rewind(zfp);
        if (!zfp_decompress(zfp, field)) throw std::runtime_error("zfp decompress failed");
        const auto t2 = Clock::now();
        if (std::memcmp(back.data(), values.data(), values.size() * 4)) throw std::runtime_error("zfp reversible is not lossless here");
        zfp_field_free(field), zfp_stream_close(zfp), stream_close(stream);
        enc.push_back(seconds(t0, t1)), dec.push_back(seconds(t1, t2));
    }
    out.encodeSeconds = median(enc), out.decodeSeconds = median(dec);
    return out;
}

nlohmann::json toJson(const Coded& c) { return {{"bytes", c.bytes}, {"encode_s", c.encodeSeconds}, {"decode_s", c.decodeSeconds}}; }

} // namespace

int main(int argc, char** argv) {
    std::string path, gridName;
    int repeats = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--grid" && i + 1 < argc) gridName = argv[++i];
        else if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
        else if (path.empty() && a[0] != '-') path = a;
        else {
            std::fprintf(stderr, "usage: vdbdag_float_bench FILE.vdb [--grid NAME] [--repeats R]\n");
            return 2;
        }
    }
    if (path.empty()) {
        std::fprintf(stderr, "usage: vdbdag_float_bench FILE.vdb [--grid NAME] [--repeats R]\n");
        return 2;
    }
    try {
        openvdb::initialize();
        openvdb::io::File file(path);
        file.open(false);
        openvdb::FloatGrid::Ptr grid;
        for (auto it = file.beginName(); it != file.endName() && !grid; ++it)
            if (gridName.empty() || it.gridName() == gridName) grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(it.gridName()));
        if (!grid) throw std::runtime_error("no float grid" + (gridName.empty() ? std::string() : " named " + gridName));
        std::vector<float> stacked, active;
        size_t leaves = 0;
        for (auto it = grid->tree().cbeginLeaf(); it; ++it, ++leaves) {
            const float* b = it->buffer().data();
            stacked.insert(stacked.end(), b, b + 512);
            for (auto v = it->cbeginValueOn(); v; ++v) active.push_back(*v);
        }
        unsigned shift = 31;
        for (const float v : active)
            if (const uint32_t m = std::bit_cast<uint32_t>(v) & 0x7FFFFFFFu) shift = std::min(shift, unsigned(std::countr_zero(m)));
        for (const float v : stacked)  // fpzip keeps the stacked array's precision too
            if (const uint32_t m = std::bit_cast<uint32_t>(v) & 0x7FFFFFFFu) shift = std::min(shift, unsigned(std::countr_zero(m)));
        const int prec = int(32 - std::min(shift, 23u));
        const Coded fpStacked = fpzipOf(stacked, 8, 8, int(8 * leaves), prec, repeats);
        const Coded fpActive = fpzipOf(active, int(active.size()), 1, 1, prec, repeats);
        const Coded& fpBest = fpActive.bytes < fpStacked.bytes ? fpActive : fpStacked;
        const Coded zfp = zfpReversibleOf(stacked, leaves, repeats);
        nlohmann::json out = {{"file", path},
                              {"grid", grid->getName()},
                              {"class", openvdb::GridBase::gridClassToString(grid->getGridClass())},
                              {"leaves", leaves},
                              {"leaf_active_voxels", active.size()},
                              {"fpzip_precision", prec},
                              {"fpzip_stacked_leaves", toJson(fpStacked)},
                              {"fpzip_active_values", toJson(fpActive)},
                              {"fpzip_best", toJson(fpBest)},
                              {"zfp_reversible_stacked_leaves", toJson(zfp)},
                              {"repeats", repeats}};
        std::printf("%s\n", out.dump().c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vdbdag_float_bench: %s: %s\n", path.c_str(), e.what());
        return 1;
    }
    return 0;
}
