// What the DICOM tests share (test_dicom.cpp: the shared series against
// pydicom; test_dicom_refusals.cpp: bad and forged inputs refused in one
// line): the series of ../shared/data/medical/dicom, pydicom's stacks of
// them (tests/tools/dicom_reference.py, never vdbdag code) and small helpers.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/util/Error.h"
#include "src/volume/GridRecord.h"
#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DicomSeries.h"

namespace vdbdag::testing::dicom {

namespace fs = std::filesystem;


inline const fs::path kDicom = fs::path(VDBDAG_SHARED_DATA) / "medical" / "dicom";
inline const fs::path kAdi = kDicom / "adi_brain";
inline const fs::path kPet = kDicom / "rsna_2" / "PET";
inline const fs::path kSeg = kDicom / "rsna_2" / "SEG";
inline const std::string kPetUid = "1.3.6.1.4.1.14519.5.2.1.2744.7002.117357550898198415937979788256";
inline const std::string kT1Uid = "1.3.12.2.1107.5.2.32.35235.2012041417312491079284166.0.0.0";     // 175 slices 192x192, one missing
inline const std::string kT2Uid = "1.3.12.2.1107.5.2.32.35235.2012041417405580603808736.0.0.0";     // 55 slices 384x512, one missing
inline const std::string kPerfUid = "1.3.12.2.1107.5.2.32.35235.2012041417554381589324478.0.0.0";   // one slice
inline const std::string kRelCbfUid = "1.3.12.2.1107.5.2.32.35235.2012041417554381589424479.0.0.0"; // one slice

inline fs::path scriptPath() { return fs::path(__FILE__).parent_path().parent_path() / "tools" / "dicom_reference.py"; }

// A python with pydicom and numpy ("" when there is none): the PATH's
// python3 may be another installation than Debian's.
inline const std::string& python() {
    static const std::string found = [] {
        for (const char* candidate : {"python3", "/usr/bin/python3"})
            if (runShell(std::string(candidate) + " -c 'import pydicom, numpy' >/dev/null").exitCode == 0) return std::string(candidate);
        return std::string();
    }();
    return found;
}

// Skips a test where the shared series or pydicom are missing.
#define REQUIRE_REFERENCE()                                                                                                  \
    do {                                                                                                                     \
        namespace d = vdbdag::testing::dicom;                                                                                \
        if (!d::fs::is_directory(d::kAdi) || !d::fs::is_directory(d::kPet)) GTEST_SKIP() << "../shared/data/medical absent"; \
        if (d::python().empty()) GTEST_SKIP() << "python3 with pydicom not available";                                      \
    } while (0)

inline fs::path workDir() {
    struct Dir {
        fs::path path = fs::temp_directory_path() / ("vdbdag_dicom_" + std::to_string(getpid()));
        Dir() {
            fs::remove_all(path);  // a finished process with the same PID may have left it
            fs::create_directories(path);
        }
        ~Dir() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    };
    static const Dir dir;
    return dir.path;
}

inline fs::path freshDir(const std::string& name) {
    const fs::path d = workDir() / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

inline std::string quote(const fs::path& p) { return "'" + p.string() + "'"; }

inline std::vector<uint8_t> readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

struct Reference {
    nlohmann::json meta;
    std::vector<uint8_t> raw;
};

// pydicom's stack of series `uid` in `folder`.
inline Reference reference(const fs::path& folder, const std::string& uid) {
    static int counter = 0;
    const fs::path out = workDir() / ("ref" + std::to_string(counter++));
    const auto r = runShell(python() + " " + quote(scriptPath()) + " stack " + quote(folder) + " " + uid + " " + quote(out));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    Reference ref;
    std::ifstream in(out.string() + ".json");
    ref.meta = nlohmann::json::parse(in);
    ref.raw = readAll(out.string() + ".raw");
    return ref;
}

inline std::vector<uint8_t> readSamples(const bridge::DenseVolume& v) {
    std::vector<uint8_t> all, part;
    const std::unique_ptr<bridge::SliceReader> reader = bridge::openDicomSlices(v);
    for (int64_t z = 0; z < v.dims[2]; z += 7) {  // an odd slab size on purpose
        reader->readSlices(std::min<int64_t>(7, v.dims[2] - z), part);
        all.insert(all.end(), part.begin(), part.end());
    }
    return all;
}

inline void expectGeometry(const bridge::DenseVolume& v, const nlohmann::json& m) {
    for (int a = 0; a < 3; ++a) EXPECT_EQ(v.dims[size_t(a)], m["dims"][a].get<int64_t>()) << "axis " << a;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.origin[size_t(c)], m["origin"][c].get<double>(), 1e-6);
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.axes[size_t(a)][size_t(c)], m["axes"][a][c].get<double>(), 1e-6) << "axis " << a << " component " << c;
    EXPECT_EQ(v.rescaleSlope, m["slope"].get<double>());
    EXPECT_EQ(v.rescaleIntercept, m["intercept"].get<double>());
    EXPECT_EQ(v.space, "LPS");
}

// The grid's transform (world = [i j k 1] * M) against pydicom's origin and axes.
inline void expectTransform(const GridRecord& g, const nlohmann::json& m) {
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.indexToWorld[size_t(a * 4 + c)], m["axes"][a][c].get<double>(), 1e-6);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.indexToWorld[size_t(12 + c)], m["origin"][c].get<double>(), 1e-6);
}

// Calls fn(x, y, z, value) for every active voxel of a dense import (T its value type).
template <typename T, typename F>
inline void forEachVoxel(const GridRecord& g, F fn) {
    // Each voxel of a brick, then of a tile (a scan's solid 8^3 blocks), with its value.
    const T* values = reinterpret_cast<const T*>(g.values.bricks.data());
    uint64_t index = 0;
    for (const auto& b : g.topology.bricks)
        for (int bit = 0; bit < 64; ++bit)
            if (b.mask >> bit & 1) fn(int64_t(b.x + (bit & 3)), int64_t(b.y + ((bit >> 2) & 3)), int64_t(b.z + (bit >> 4)), values[index++]);
    const T* tileValues = reinterpret_cast<const T*>(g.values.tiles.data());
    for (size_t t = 0; t < g.topology.tiles.size(); ++t) {
        const auto& tile = g.topology.tiles[t];
        const int64_t n = int64_t(1) << tile.log2Size;
        for (int64_t z = 0; z < n; ++z)
            for (int64_t y = 0; y < n; ++y)
                for (int64_t x = 0; x < n; ++x) fn(tile.x + x, tile.y + y, tile.z + z, tileValues[t]);
    }
}

inline bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

inline std::string errorOf(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const vdbdag::Error& e) {
        return e.what();
    }
    return "";
}

// Copies `files` into `dir` under new names (reversed order: the last file
// first), so names say nothing of positions.
inline void copyRenamed(const std::vector<std::string>& files, const fs::path& dir, unsigned seed) {
    std::vector<size_t> names(files.size());
    for (size_t i = 0; i < names.size(); ++i) names[i] = files.size() - i;
    std::mt19937 rng(seed);
    std::shuffle(names.begin(), names.end(), rng);
    for (size_t i = 0; i < files.size(); ++i) fs::copy_file(files[i], dir / ("IM" + std::to_string(1000 + names[i])));
}

// The PET files in slice order (pydicom's): their names say nothing of it.
inline const std::vector<std::string>& petByPosition() {
    static const std::vector<std::string> files = [] {
        std::vector<std::string> out;
        const Reference ref = reference(kPet, kPetUid);
        for (const auto& f : ref.meta["files"]) out.push_back(f.get<std::string>());
        return out;
    }();
    return files;
}

inline bridge::DenseImportOptions quietOptions(const std::string& series = "") {
    bridge::DenseImportOptions o;
    o.showProgress = false;
    o.series = series;
    return o;
}

} // namespace vdbdag::testing::dicom
