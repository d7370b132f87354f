// libFuzzer target for the .ssvdag reader. Each input is read two ways:
//   1. summarizeContainer and readContainer on the bytes as given (magic,
//      version, table bounds, checksums), and what validates goes on through
//      sectionsToScene (section parsers, DAG validation) and a DAG walk;
//   2. the same bytes with every checksum the table makes reachable patched
//      to match, so mutations of the table and payloads get past the xxh3
//      checks and reach the bounds, overlap, raw-size and zstd checks.
//   3. a file that reads as a scene is also read from a file as `info` and
//      the reader library read it: its headers alone (ReadOptions::
//      headersOnly), then vdbdag::File::open and each grid's first walk
//      (its DAGs and values read then, GridData::load) and one lookup.
// Any input must end in success or vdbdag::Error; anything else (a crash, a
// sanitizer report, another exception, a timeout or an out-of-memory) is a
// bug, and so is summarizeContainer disagreeing with readContainer.
// Run: scripts/fuzz.sh [SECONDS]
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include <unistd.h>
#include <vdbdag/vdbdag.h>
#include <xxhash.h>

#include "src/encoding/CompactDag.h"
#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"
#include "src/util/Error.h"

namespace {

using namespace vdbdag;

constexpr uint64_t kMaxRawBytes = uint64_t(64) << 20;

uint64_t load64(const uint8_t* p) {
    uint64_t v;
    std::memcpy(&v, p, 8);
    return v;
}

// Rewrites the payload checksums of in-bounds entries and the table checksum.
void patchChecksums(std::vector<uint8_t>& b) {
    if (b.size() < 24) return;
    uint32_t count;
    std::memcpy(&count, b.data() + 12, 4);
    const uint64_t tableEnd = 16 + uint64_t(count) * 48;
    if (tableEnd + 8 > b.size()) return;
    for (uint64_t e = 16; e < tableEnd; e += 48) {
        const uint64_t offset = load64(&b[e + 16]), stored = load64(&b[e + 24]);
        if (offset > b.size() || stored > b.size() - offset) continue;
        const uint64_t sum = XXH3_64bits(b.data() + offset, stored);
        std::memcpy(&b[e + 40], &sum, 8);
    }
    const uint64_t sum = XXH3_64bits(b.data(), tableEnd);
    std::memcpy(&b[tableEnd], &sum, 8);
}

// 3. above, for bytes that read as a scene: written to a file in /dev/shm.
void readAsFile(std::span<const uint8_t> bytes, const format::ReadLimits& limits) {
    static const std::string path = "/dev/shm/fuzz_ssvdag_reader_" + std::to_string(::getpid()) + ".ssvdag";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    try {
        format::ReadOptions headers;
        headers.limits = limits;
        headers.headersOnly = true;
        (void)format::readSceneFile(path, headers);
    } catch (const Error&) {
    }
    try {
        const File file = File::open(path, OpenLimits{limits.maxVoxels, limits.maxMemory});
        for (size_t g = 0; g < file.gridCount(); ++g) {
            const Grid& grid = file.grid(g);
            const IndexBBox box = grid.indexBBox();
            try {
                Accessor a = grid.accessor();
                uint8_t value[32] = {};
                if (!box.empty() && grid.valueSize() <= sizeof(value)) a.valueBytes(box.min[0], box.min[1], box.min[2], value);
            } catch (const Error&) {
            }
        }
    } catch (const Error&) {
    }
    std::remove(path.c_str());  // nothing left in /dev/shm
}

void readAll(std::span<const uint8_t> bytes, bool deep) {
    std::vector<format::SectionSummary> summary;
    bool summarized = false;
    try {
        summary = format::summarizeContainer(bytes, "fuzz");
        summarized = true;
    } catch (const Error&) {
    }
    // A zstd section may legitimately restore to 2^16 times its stored size
    // (the reader's bound), so a 64 KiB input can ask for 4 GiB that zstd would
    // really produce. Stay inside the fuzzer's memory limit: inputs whose
    // validated table asks for more than this are only summarized.
    if (summarized) {
        uint64_t raw = 0;
        for (const auto& s : summary) raw += s.rawBytes;
        if (raw > kMaxRawBytes) return;
    }
    std::vector<format::Section> sections;
    try {
        sections = format::readContainer(bytes, "fuzz");
    } catch (const Error&) {
        return;
    }
    // readContainer accepted it: summarizeContainer must have, with the same table.
    if (!summarized || summary.size() != sections.size()) __builtin_trap();
    for (size_t i = 0; i < sections.size(); ++i)
        if (summary[i].kind != sections[i].kind || summary[i].grid != sections[i].grid || summary[i].rawBytes != sections[i].data.size())
            __builtin_trap();
    if (!deep) return;
    try {
        // As a command reads a file from elsewhere: within read limits (a
        // forged expansion or a legacy Values section may decode to far more
        // than the fuzzer's memory; the limits refuse it before decoding).
        format::ReadOptions options;
        options.limits.maxVoxels = uint64_t(1) << 22;
        options.limits.maxMemory = uint64_t(512) << 20;
        // A sequence file: one frame read alone too (the second, or the only one).
        if (std::any_of(sections.begin(), sections.end(), [](const format::Section& s) { return s.kind == format::SectionKind::Frames; })) {
            format::ReadOptions one = options;
            one.frame = 1;
            try {
                format::sectionsToScene(sections, "fuzz", one);
            } catch (const Error&) {
            }
        }
        const format::SsvdagScene scene = format::sectionsToScene(std::move(sections), "fuzz", options);
        readAsFile(bytes, options.limits);
        for (const auto& grid : scene.grids) {
            // An expansion bomb (a few KB that decode to 2^40 bricks) is a
            // valid file the readers bound by --max-voxels; the walk below is
            // only for DAGs that decode to at most 2^20 bricks and tiles, so a
            // bomb as a seed never times the run out (issue 38 #11).
            const encoding::DecodedSize size = encoding::decodedSize(grid.active.dag);
            if (size.emittedBricks > (uint64_t(1) << 20) || size.emittedTiles > (uint64_t(1) << 20)) continue;
            uint64_t visited = 0;
            encoding::visitInstances(
                grid.active.dag, [&](int64_t, int64_t, int64_t, uint64_t) { ++visited; }, [&](int64_t, int64_t, int64_t, unsigned) { ++visited; });
        }
    } catch (const Error&) {
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    readAll(bytes, true);
    std::vector<uint8_t> patched(data, data + size);
    patchChecksums(patched);
    if (patched != std::vector<uint8_t>(data, data + size)) readAll(patched, true);
    return 0;
}
