// Mapping between SsvdagScene and container sections. Section payloads:
//   FileInfo      u32 grid count, string writer
//   GridInfo      string name, string class, u8 value type, u8 symmetry,
//                 f64[16] index-to-world, u64 active voxels
//   VdbDescriptor opaque bytes (vdb_bridge)
//   DagLevels     i64[3] origin, u8 log2Size, u8 root reflection,
//                 u32 n, u64[n] level starts, u8[n] attribute-offset words,
//                 u64 inner words, u64 leaves
//   DagInner      u16[inner words]     (absent for an empty grid)
//   DagLeaves     u64[leaves]          (absent for an empty grid)
//   DagStats      u32 n, u8 hasSvdag, then n x (u64 svo, u64 svdag, u64 stored)
// Strings are u32 length + bytes. Everything little-endian (ByteIO.h).
#include "src/format/SsvdagFile.h"

#include <map>

#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::format {
namespace {

constexpr const char* kWriter = "vdbdag 0.1";

template <typename T>
std::vector<uint8_t> rawBytes(const std::vector<T>& values) {
    const auto* p = reinterpret_cast<const uint8_t*>(values.data());
    return std::vector<uint8_t>(p, p + values.size() * sizeof(T));
}

template <typename T>
std::vector<T> fromRawBytes(const std::vector<uint8_t>& bytes, uint64_t expectedCount, const std::string& what) {
    if (bytes.size() % sizeof(T) != 0 || bytes.size() / sizeof(T) != expectedCount)
        throw Error(what + ": holds " + std::to_string(bytes.size()) + " bytes, expected " + std::to_string(expectedCount * sizeof(T)));
    std::vector<T> values(expectedCount);
    std::memcpy(values.data(), bytes.data(), bytes.size());
    return values;
}

} // namespace

std::vector<Section> sceneToSections(const SsvdagScene& scene) {
    std::vector<Section> sections;
    {
        ByteWriter w;
        w.put<uint32_t>(uint32_t(scene.grids.size()));
        w.putString(kWriter);
        sections.push_back({SectionKind::FileInfo, 0, w.take()});
    }
    for (uint32_t g = 0; g < scene.grids.size(); ++g) {
        const EncodedGrid& grid = scene.grids[g];
        ByteWriter info;
        info.putString(grid.record.name);
        info.putString(grid.record.gridClass);
        info.put<uint8_t>(uint8_t(grid.record.valueType));
        info.put<uint8_t>(grid.symmetry ? 1 : 0);
        for (double v : grid.record.indexToWorld) info.put<double>(v);
        info.put<uint64_t>(grid.activeVoxels);
        sections.push_back({SectionKind::GridInfo, g, info.take()});
        sections.push_back({SectionKind::VdbDescriptor, g, grid.record.vdbDescriptor});

        const encoding::CompactDag& dag = grid.dag;
        ByteWriter levels;
        for (int64_t o : dag.origin) levels.put<int64_t>(o);
        levels.put<uint8_t>(dag.log2Size);
        levels.put<uint8_t>(dag.rootReflection);
        levels.put<uint32_t>(uint32_t(dag.levelStart.size()));
        for (uint64_t s : dag.levelStart) levels.put<uint64_t>(s);
        for (uint8_t w : dag.offsetWords) levels.put<uint8_t>(w);
        levels.put<uint64_t>(dag.inner.size());
        levels.put<uint64_t>(dag.leaves.size());
        sections.push_back({SectionKind::DagLevels, g, levels.take()});
        if (!dag.empty()) {
            sections.push_back({SectionKind::DagInner, g, rawBytes(dag.inner)});
            sections.push_back({SectionKind::DagLeaves, g, rawBytes(dag.leaves)});
        }
        ByteWriter stats;
        const DagStats& st = grid.stats;
        stats.put<uint32_t>(uint32_t(st.svoNodes.size()));
        stats.put<uint8_t>(st.hasSvdag ? 1 : 0);
        for (size_t i = 0; i < st.svoNodes.size(); ++i) {
            stats.put<uint64_t>(st.svoNodes[i]);
            stats.put<uint64_t>(i < st.svdagNodes.size() ? st.svdagNodes[i] : 0);
            stats.put<uint64_t>(i < st.storedNodes.size() ? st.storedNodes[i] : 0);
        }
        sections.push_back({SectionKind::DagStats, g, stats.take()});
    }
    return sections;
}

SsvdagScene sectionsToScene(std::vector<Section> sections, const std::string& sourceName) {
    const Section* fileInfo = nullptr;
    std::map<std::pair<uint32_t, SectionKind>, Section*> byGrid;
    for (Section& s : sections) {
        if (s.kind == SectionKind::FileInfo) {
            if (fileInfo) throw Error(sourceName + ": two FileInfo sections");
            fileInfo = &s;
            continue;
        }
        if (!byGrid.emplace(std::make_pair(s.grid, s.kind), &s).second)
            throw Error(sourceName + ": duplicate section '" + sectionKindName(s.kind) + "' for grid " + std::to_string(s.grid));
    }
    if (!fileInfo) throw Error(sourceName + ": missing FileInfo section");
    ByteReader fr(fileInfo->data, sourceName + ": FileInfo");
    const uint32_t gridCount = fr.get<uint32_t>();
    fr.getString();
    if (gridCount > sections.size()) throw Error(sourceName + ": FileInfo claims " + std::to_string(gridCount) + " grids, more than its sections can hold");

    auto find = [&](uint32_t g, SectionKind kind, bool required) -> Section* {
        auto it = byGrid.find({g, kind});
        if (it == byGrid.end()) {
            if (required) throw Error(sourceName + ": grid " + std::to_string(g) + " has no '" + sectionKindName(kind) + "' section");
            return nullptr;
        }
        return it->second;
    };

    SsvdagScene scene;
    scene.grids.resize(gridCount);
    for (uint32_t g = 0; g < gridCount; ++g) {
        EncodedGrid& grid = scene.grids[g];
        const std::string what = sourceName + ": grid " + std::to_string(g);
        {
            ByteReader r(find(g, SectionKind::GridInfo, true)->data, what + " GridInfo");
            grid.record.name = r.getString();
            grid.record.gridClass = r.getString();
            const uint8_t type = r.get<uint8_t>();
            if (type > uint8_t(ValueType::Vec3I)) r.fail("unknown value type " + std::to_string(type));
            grid.record.valueType = ValueType(type);
            grid.symmetry = r.get<uint8_t>() != 0;
            for (double& v : grid.record.indexToWorld) v = r.get<double>();
            grid.activeVoxels = r.get<uint64_t>();
            r.expectEnd();
        }
        grid.record.vdbDescriptor = std::move(find(g, SectionKind::VdbDescriptor, true)->data);
        encoding::CompactDag& dag = grid.dag;
        uint64_t innerWords = 0, leafCount = 0;
        {
            ByteReader r(find(g, SectionKind::DagLevels, true)->data, what + " DagLevels");
            for (int64_t& o : dag.origin) o = r.get<int64_t>();
            dag.log2Size = r.get<uint8_t>();
            dag.rootReflection = r.get<uint8_t>();
            const uint32_t n = r.get<uint32_t>();
            dag.levelStart = r.getArray<uint64_t>(n);
            dag.offsetWords = r.getArray<uint8_t>(n);
            innerWords = r.get<uint64_t>();
            leafCount = r.get<uint64_t>();
            r.expectEnd();
        }
        Section* inner = find(g, SectionKind::DagInner, dag.log2Size != 0);
        Section* leaves = find(g, SectionKind::DagLeaves, dag.log2Size != 0);
        if (inner) dag.inner = fromRawBytes<uint16_t>(inner->data, innerWords, what + " DagInner");
        else if (innerWords) throw Error(what + ": DagLevels claims inner words but there is no DagInner section");
        if (leaves) dag.leaves = fromRawBytes<uint64_t>(leaves->data, leafCount, what + " DagLeaves");
        else if (leafCount) throw Error(what + ": DagLevels claims leaves but there is no DagLeaves section");
        for (uint64_t s : dag.levelStart)
            if (s > dag.inner.size()) throw Error(what + ": level start " + std::to_string(s) + " beyond the inner array");
        encoding::validateCompact(dag, what);
        const encoding::DecodedSize size = encoding::decodedSize(dag);
        if (size.activeVoxels != grid.activeVoxels)
            throw Error(what + ": the DAG holds " + std::to_string(size.activeVoxels) + " active voxels but the header says " +
                        std::to_string(grid.activeVoxels) + "; the file is corrupted");
        if (Section* st = find(g, SectionKind::DagStats, false)) {
            ByteReader r(st->data, what + " DagStats");
            const uint32_t n = r.get<uint32_t>();
            if (n > 64) r.fail("implausible level count");
            grid.stats.hasSvdag = r.get<uint8_t>() != 0;
            for (uint32_t i = 0; i < n; ++i) {
                grid.stats.svoNodes.push_back(r.get<uint64_t>());
                grid.stats.svdagNodes.push_back(r.get<uint64_t>());
                grid.stats.storedNodes.push_back(r.get<uint64_t>());
            }
            r.expectEnd();
        }
    }
    for (const auto& [key, section] : byGrid)
        if (key.first >= gridCount) throw Error(sourceName + ": section for grid " + std::to_string(key.first) + " but the file has " + std::to_string(gridCount) + " grids");
    return scene;
}

std::vector<uint8_t> writeScene(const SsvdagScene& scene, const ContainerOptions& options) {
    return writeContainer(sceneToSections(scene), options);
}

SsvdagScene readScene(std::span<const uint8_t> bytes, const std::string& sourceName) {
    return sectionsToScene(readContainer(bytes, sourceName), sourceName);
}

SsvdagScene readSceneFile(const std::string& path) {
    const std::vector<uint8_t> bytes = readFileBytes(path);
    return readScene(bytes, path);
}

} // namespace vdbdag::format
