// vdbdag_vdb_probe: an independent OpenVDB-only reference for the vdbdag
// safety tests. It includes no vdbdag header on purpose: everything it
// reports comes from OpenVDB's own reader.
//
//   vdbdag_vdb_probe meta FILE    JSON: file metadata, grids in file order, grid metadata
//                                 and index_to_world (4x4 row-major, a linear map)
//   vdbdag_vdb_probe same A B     exit 0 iff A and B hold the same file metadata,
//                                 grid order, grid metadata (file_* rule below)
//                                 and the same trees (type, transform,
//                                 background, active voxels and tiles, values
//                                 bit for bit); prints what differs otherwise
//   vdbdag_vdb_probe read FILE    reads every grid and every leaf buffer; exit 0,
//                                 or prints the error and exits 1
//   vdbdag_vdb_probe values FILE GRID
//                                 for each line "i j k" of stdin prints "A HEX",
//                                 from OpenVDB's accessor: A is 1 if the voxel
//                                 is active, HEX the value's bytes in memory
//                                 order ("-" for a mask grid)
//   vdbdag_vdb_probe sample FILE GRID N SEED
//                                 prints N lines "i j k": every other one an
//                                 active voxel of a leaf drawn at random, the
//                                 rest uniform in the active bounding box
//                                 grown by 8 voxels
//
// The file_* rule: OpenVDB rewrites the per-grid statistics metadata on every
// write. file_bbox_min, file_bbox_max and file_voxel_count must be equal when
// both files hold them; file_mem_bytes, file_compression and file_delayed_load
// are reported ("note:") but never make the files differ.
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <cstring>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

// io::File lists its grids (getGrids, readAllGridMetadata) in the order of
// its private name-keyed descriptor map, sorted by name, not in file order.
// io::File befriends a class ::TestFile (for OpenVDB's own unit tests); this
// one only reads the descriptors' file positions, to restore the file order.
class TestFile {
public:
    // File positions of the grids, in the order io::File lists them.
    static std::vector<int64_t> gridPositions(const openvdb::io::File& f) {
        std::vector<int64_t> out;
        for (const auto& [name, gd] : f.gridDescriptors()) out.push_back(gd.getGridPos());
        return out;
    }
};

namespace {

using openvdb::GridBase;
using openvdb::MetaMap;

const std::set<std::string> kStatsMustMatch = {"file_bbox_min", "file_bbox_max", "file_voxel_count"};
const std::set<std::string> kStatsMayDiffer = {"file_mem_bytes", "file_compression", "file_delayed_load"};
constexpr int kMaxExamples = 8;

std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (c < 0x20 || c >= 0x7f) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += char(c);
                }
        }
    }
    return out + "\"";
}

// The metadata's value exactly as OpenVDB serialises it.
std::string metaBytes(const openvdb::Metadata& m) {
    std::ostringstream os(std::ios::binary);
    m.write(os);  // size and value, as stored in the file
    return os.str();
}

std::string metaText(const openvdb::Metadata& m) {
    try {
        return m.str();
    } catch (...) {
        return "<unprintable>";
    }
}

std::map<std::string, openvdb::Metadata::ConstPtr> metaOf(const MetaMap& mm) {
    std::map<std::string, openvdb::Metadata::ConstPtr> out;
    for (auto it = mm.beginMeta(); it != mm.endMeta(); ++it) out[it->first] = it->second;
    return out;
}

std::string metaJson(const MetaMap& mm) {
    std::string out = "[";
    bool first = true;
    for (const auto& [name, m] : metaOf(mm)) {
        if (!first) out += ", ";
        first = false;
        out += "{\"name\": " + jsonString(name) + ", \"type\": " + jsonString(m ? m->typeName() : "null") +
               ", \"value\": " + jsonString(m ? metaText(*m) : "") + "}";
    }
    return out + "]";
}

struct FileContents {
    MetaMap::Ptr fileMeta;
    openvdb::GridPtrVecPtr grids;  // metadata only, or full grids
};

FileContents openFile(const std::string& path, bool withTrees) {
    openvdb::io::File f(path);
    f.open(/*delayLoad=*/false);
    FileContents c;
    c.fileMeta = f.getMetadata();
    c.grids = withTrees ? f.getGrids() : f.readAllGridMetadata();
    if (!c.fileMeta) c.fileMeta = std::make_shared<MetaMap>();
    if (!c.grids) c.grids = std::make_shared<openvdb::GridPtrVec>();
    // Back into file order (the position of each grid in the file).
    const std::vector<int64_t> pos = TestFile::gridPositions(f);
    f.close();
    if (pos.size() != c.grids->size()) throw std::runtime_error(path + ": grid descriptors and grids disagree in number");
    std::vector<size_t> order(pos.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return pos[x] < pos[y]; });
    auto sorted = std::make_shared<openvdb::GridPtrVec>();
    for (size_t i : order) sorted->push_back((*c.grids)[i]);
    c.grids = sorted;
    return c;
}

std::string fmt17(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

int cmdMeta(const std::string& path) {
    const FileContents c = openFile(path, false);
    std::cout << "{\n  \"file\": " << jsonString(path) << ",\n  \"file_metadata\": " << metaJson(*c.fileMeta) << ",\n  \"grids\": [";
    for (size_t i = 0; i < c.grids->size(); ++i) {
        const GridBase& g = *(*c.grids)[i];
        std::cout << (i ? ",\n" : "\n") << "    {\"index\": " << i << ", \"name\": " << jsonString(g.getName()) << ", \"type\": " << jsonString(g.type())
                  << ", \"index_to_world\": [";
        // The transform as a 4x4 row-major matrix (world = [i j k 1] * M), for a linear map.
        const openvdb::math::MapBase::ConstPtr map = g.transform().baseMap();
        if (map->isLinear()) {
            const openvdb::Mat4d m = map->getAffineMap()->getMat4();
            for (int r = 0; r < 4; ++r)
                for (int col = 0; col < 4; ++col) std::cout << (r || col ? ", " : "") << fmt17(m(r, col));
        }
        std::cout << "], \"metadata\": " << metaJson(g) << "}";
    }
    std::cout << "\n  ]\n}\n";
    return 0;
}

// Appends to `diffs` what differs between two metadata maps; notes (never
// failures) go to `notes`.
void compareMeta(const std::string& where, const MetaMap& a, const MetaMap& b, bool statsRule, std::vector<std::string>& diffs,
                 std::vector<std::string>& notes) {
    const auto ma = metaOf(a), mb = metaOf(b);
    std::set<std::string> names;
    for (const auto& [n, m] : ma) names.insert(n);
    for (const auto& [n, m] : mb) names.insert(n);
    for (const std::string& n : names) {
        const auto ia = ma.find(n), ib = mb.find(n);
        const bool inA = ia != ma.end() && ia->second, inB = ib != mb.end() && ib->second;
        const bool mayDiffer = statsRule && kStatsMayDiffer.count(n);
        const bool onlyIfBoth = statsRule && kStatsMustMatch.count(n);
        if (!inA || !inB) {
            const std::string msg = where + " metadata '" + n + "' only in " + (inA ? "A" : "B") + " (" +
                                    metaText(inA ? *ia->second : *ib->second) + ")";
            if (mayDiffer || onlyIfBoth) notes.push_back(msg);
            else diffs.push_back(msg);
            continue;
        }
        const openvdb::Metadata& x = *ia->second;
        const openvdb::Metadata& y = *ib->second;
        if (x.typeName() != y.typeName() || metaBytes(x) != metaBytes(y)) {
            const std::string msg = where + " metadata '" + n + "': A " + x.typeName() + " '" + metaText(x) + "', B " + y.typeName() + " '" +
                                    metaText(y) + "'";
            if (mayDiffer) notes.push_back(msg);
            else diffs.push_back(msg);
        }
    }
}

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) {
        return a == b;
    } else {
        static_assert(std::is_trivially_copyable_v<T>);
        return std::memcmp(&a, &b, sizeof(T)) == 0;
    }
}

template <typename T>
std::string valueText(const T& v) {
    std::ostringstream os;
    os.precision(9);
    os << v;
    return os.str();
}

std::string coordText(const openvdb::Coord& c) {
    std::ostringstream os;
    os << c;
    return os.str();
}

// Active topology and values of A that are missing or different in B.
template <typename GridT>
uint64_t activeNotIn(const GridT& a, const GridT& b, const std::string& where, const char* aName, const char* bName,
                     std::vector<std::string>& diffs) {
    using TreeT = typename GridT::TreeType;
    const TreeT& ta = a.tree();
    const TreeT& tb = b.tree();
    auto acc = b.getConstAccessor();
    uint64_t bad = 0;
    auto report = [&](const std::string& what) {
        if (bad++ < kMaxExamples) diffs.push_back(where + ": " + what);
    };
    // Tiles (every level above the leaves).
    for (auto it = ta.cbeginValueOn(); it; ++it) {
        if (!it.isTileValue()) continue;
        const openvdb::Coord c = it.getCoord();
        const int depth = it.getDepth();
        if (!acc.isValueOn(c) || acc.getValueDepth(c) != depth)
            report(std::string("active tile at ") + coordText(c) + " (depth " + std::to_string(depth) + ") of " + aName + " is not an active tile of the same size in " +
                   bName);
        else if (!sameBits(*it, acc.getValue(c)))
            report(std::string("active tile at ") + coordText(c) + ": " + aName + " " + valueText(*it) + ", " + bName + " " + valueText(acc.getValue(c)));
    }
    // Leaf voxels.
    for (auto leaf = ta.cbeginLeaf(); leaf; ++leaf) {
        if (leaf->getValueMask().isOff()) continue;
        const auto* other = tb.probeConstLeaf(leaf->origin());
        for (auto v = leaf->cbeginValueOn(); v; ++v) {
            const openvdb::Coord c = v.getCoord();
            if (!other) {
                if (!acc.isValueOn(c)) report(std::string("active voxel ") + coordText(c) + " of " + aName + " is inactive in " + bName);
                else report(std::string("active voxel ") + coordText(c) + " of " + aName + " is inside an active tile in " + bName);
                continue;
            }
            const auto idx = v.pos();
            if (!other->isValueOn(idx)) report(std::string("active voxel ") + coordText(c) + " of " + aName + " is inactive in " + bName);
            else if (!sameBits(*v, other->getValue(idx)))
                report(std::string("voxel ") + coordText(c) + ": " + aName + " " + valueText(*v) + ", " + bName + " " + valueText(other->getValue(idx)));
        }
    }
    return bad;
}

struct TreeCompare {
    const GridBase& other;
    const std::string& where;
    std::vector<std::string>& diffs;
    template <typename GridT>
    void operator()(const GridT& a) const {
        const GridT& b = static_cast<const GridT&>(other);
        if (!sameBits(a.background(), b.background()))
            diffs.push_back(where + ": background A " + valueText(a.background()) + ", B " + valueText(b.background()));
        const uint64_t x = activeNotIn(a, b, where, "A", "B", diffs);
        const uint64_t y = activeNotIn(b, a, where, "B", "A", diffs);
        if (x + y > 0)
            diffs.push_back(where + ": " + std::to_string(x) + " active values of A missing/different in B, " + std::to_string(y) +
                            " of B missing/different in A");
        if (a.tree().activeVoxelCount() != b.tree().activeVoxelCount())
            diffs.push_back(where + ": active voxel count A " + std::to_string(a.tree().activeVoxelCount()) + ", B " +
                            std::to_string(b.tree().activeVoxelCount()));
    }
};

std::string transformBytes(const GridBase& g) {
    std::ostringstream os(std::ios::binary);
    g.transform().write(os);
    return os.str();
}

int cmdSame(const std::string& pa, const std::string& pb) {
    const FileContents a = openFile(pa, true), b = openFile(pb, true);
    std::vector<std::string> diffs, notes;
    compareMeta("file", *a.fileMeta, *b.fileMeta, false, diffs, notes);
    if (a.grids->size() != b.grids->size())
        diffs.push_back("grid count: A " + std::to_string(a.grids->size()) + ", B " + std::to_string(b.grids->size()));
    const size_t n = std::min(a.grids->size(), b.grids->size());
    for (size_t i = 0; i < n; ++i) {
        const GridBase& ga = *(*a.grids)[i];
        const GridBase& gb = *(*b.grids)[i];
        const std::string where = "grid " + std::to_string(i) + " '" + ga.getName() + "'";
        if (ga.getName() != gb.getName()) diffs.push_back(where + ": name in B is '" + gb.getName() + "' (grid order or name changed)");
        compareMeta(where, ga, gb, true, diffs, notes);
        if (ga.type() != gb.type()) {
            diffs.push_back(where + ": type A " + ga.type() + ", B " + gb.type());
            continue;
        }
        if (transformBytes(ga) != transformBytes(gb)) {
            std::ostringstream ta, tb;
            ga.transform().print(ta);
            gb.transform().print(tb);
            diffs.push_back(where + ": transforms differ (A " + ta.str() + "; B " + tb.str() + ")");
        }
        const TreeCompare op{gb, where, diffs};
        if (!ga.apply<openvdb::GridTypes>(op)) diffs.push_back(where + ": grid type " + ga.type() + " cannot be compared by this probe");
    }
    for (const auto& s : notes) std::cout << "note: " << s << "\n";
    for (const auto& s : diffs) std::cout << "DIFF: " << s << "\n";
    std::cout << pa << " vs " << pb << ": " << (diffs.empty() ? "same" : "DIFFERENT") << "\n";
    return diffs.empty() ? 0 : 1;
}

int cmdRead(const std::string& path) {
    const FileContents c = openFile(path, true);
    uint64_t voxels = 0, leaves = 0;
    for (const auto& g : *c.grids) {
        g->baseTree().readNonresidentBuffers();
        voxels += g->activeVoxelCount();
        leaves += g->baseTree().leafCount();
    }
    std::cout << path << ": read " << c.grids->size() << " grid(s), " << leaves << " leaves, " << voxels << " active voxels\n";
    return 0;
}

} // namespace

struct ValueLookup {
    template <typename GridT>
    void operator()(const GridT& grid) const {
        using V = typename GridT::ValueType;
        auto acc = grid.getConstAccessor();
        static const char* kHex = "0123456789abcdef";
        std::string out;
        long long i, j, k;
        while (std::cin >> i >> j >> k) {
            const openvdb::Coord c{int32_t(i), int32_t(j), int32_t(k)};
            out += acc.isValueOn(c) ? "1 " : "0 ";
            if constexpr (std::is_same_v<V, openvdb::ValueMask>) {
                out += '-';
            } else {
                const V v = acc.getValue(c);
                unsigned char bytes[sizeof(V)];
                if constexpr (std::is_same_v<V, bool>) bytes[0] = v ? 1 : 0;
                else std::memcpy(bytes, &v, sizeof(V));
                for (unsigned n = 0; n < (std::is_same_v<V, bool> ? 1u : unsigned(sizeof(V))); ++n) {
                    out += kHex[bytes[n] >> 4];
                    out += kHex[bytes[n] & 15];
                }
            }
            out += '\n';
        }
        std::cout << out;
    }
};

struct CoordSample {
    size_t n;
    uint64_t seed;
    template <typename GridT>
    void operator()(const GridT& grid) const {
        std::vector<openvdb::Coord> active;
        for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
            for (auto v = leaf->cbeginValueOn(); v; ++v) active.push_back(v.getCoord());
        const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
        std::mt19937_64 rng(seed);
        std::string out;
        for (size_t i = 0; i < n; ++i) {
            openvdb::Coord c;
            if (i % 2 == 0 && !active.empty()) {
                c = active[rng() % active.size()];
            } else {
                for (int a = 0; a < 3; ++a) {
                    const int64_t lo = int64_t(box.min()[a]) - 8, hi = int64_t(box.max()[a]) + 8;
                    c[a] = int32_t(lo + int64_t(rng() % uint64_t(hi - lo + 1)));
                }
            }
            out += std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + "\n";
        }
        std::cout << out;
    }
};

int cmdSample(const std::string& path, const std::string& name, size_t n, uint64_t seed) {
    openvdb::io::File file(path);
    file.open(false);
    const GridBase::Ptr grid = file.readGrid(name);
    if (!grid->apply<openvdb::GridTypes>(CoordSample{n, seed})) throw std::runtime_error("grid type " + grid->type() + " cannot be sampled");
    return 0;
}

int cmdValues(const std::string& path, const std::string& name) {
    openvdb::io::File file(path);
    file.open(false);
    const GridBase::Ptr grid = file.readGrid(name);
    if (!grid->apply<openvdb::GridTypes>(ValueLookup{})) throw std::runtime_error("grid type " + grid->type() + " cannot be probed");
    return 0;
}

int main(int argc, char** argv) {
    const std::string usage = "usage: vdbdag_vdb_probe meta FILE | same A B | read FILE | values FILE GRID | sample FILE GRID N SEED\n";
    if (argc < 3) {
        std::cerr << usage;
        return 2;
    }
    const std::string cmd = argv[1];
    try {
        openvdb::initialize();
        if (cmd == "meta" && argc == 3) return cmdMeta(argv[2]);
        if (cmd == "same" && argc == 4) return cmdSame(argv[2], argv[3]);
        if (cmd == "read" && argc == 3) return cmdRead(argv[2]);
        if (cmd == "values" && argc == 4) return cmdValues(argv[2], argv[3]);
        if (cmd == "sample" && argc == 6) return cmdSample(argv[2], argv[3], std::stoul(argv[4]), std::stoull(argv[5]));
        std::cerr << usage;
        return 2;
    } catch (const std::exception& e) {
        std::cout << "error: " << e.what() << "\n";
        std::cerr << "vdbdag_vdb_probe: " << e.what() << "\n";
        return 1;
    } catch (...) {
        std::cerr << "vdbdag_vdb_probe: unknown exception\n";
        return 1;
    }
}
