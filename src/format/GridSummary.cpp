// See GridSummary.h.
#include "src/format/GridSummary.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include <fmt/core.h>

#include "src/attributes/WindowCursor.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"
#include "src/volume/ValueBytes.h"

namespace vdbdag::format {
namespace {

// A node's box in its own frame (0 .. size-1 on each axis), unreflected.
struct LocalBox {
    std::array<int64_t, 3> lo{}, hi{};
    bool any = false;
    void merge(const LocalBox& o) {
        if (!o.any) return;
        for (int a = 0; a < 3; ++a) {
            lo[a] = any ? std::min(lo[a], o.lo[a]) : o.lo[a];
            hi[a] = any ? std::max(hi[a], o.hi[a]) : o.hi[a];
        }
        any = true;
    }
    // The same node reflected by `m` (node `size` wide), then moved by `at`.
    LocalBox placed(unsigned m, int64_t size, const std::array<int64_t, 3>& at) const {
        LocalBox out = *this;
        for (int a = 0; a < 3; ++a) {
            if ((m >> a) & 1u) {
                out.lo[a] = size - 1 - hi[a];
                out.hi[a] = size - 1 - lo[a];
            }
            out.lo[a] += at[a];
            out.hi[a] += at[a];
        }
        return out;
    }
};

LocalBox brickBox(uint64_t mask) {
    LocalBox b;
    for (uint64_t m = mask; m; m &= m - 1) {
        const unsigned bit = unsigned(std::countr_zero(m));
        b.merge(LocalBox{{int64_t(bit & 3u), int64_t((bit >> 2) & 3u), int64_t(bit >> 4)},
                         {int64_t(bit & 3u), int64_t((bit >> 2) & 3u), int64_t(bit >> 4)}, true});
    }
    return b;
}

template <typename T>
int compareScalar(const uint8_t* a, const uint8_t* b) {
    T x, y;
    std::memcpy(&x, a, sizeof(T));
    std::memcpy(&y, b, sizeof(T));
    return x < y ? -1 : (y < x ? 1 : 0);
}

// OpenVDB's `<` for one value: scalars as themselves, vectors
// lexicographically (math::Tuple::operator<).
int compareValues(ValueType type, const uint8_t* a, const uint8_t* b) {
    switch (type) {
    case ValueType::Float: return compareScalar<float>(a, b);
    case ValueType::Double: return compareScalar<double>(a, b);
    case ValueType::Int32: return compareScalar<int32_t>(a, b);
    case ValueType::Int64: return compareScalar<int64_t>(a, b);
    case ValueType::Bool: return compareScalar<uint8_t>(a, b);
    case ValueType::Mask: return 0;
    case ValueType::Vec3S:
    case ValueType::Vec3D:
    case ValueType::Vec3I: {
        const unsigned c = valueSize(type) / 3;
        for (unsigned i = 0; i < 3; ++i) {
            const int r = type == ValueType::Vec3S   ? compareScalar<float>(a + i * c, b + i * c)
                          : type == ValueType::Vec3D ? compareScalar<double>(a + i * c, b + i * c)
                                                     : compareScalar<int32_t>(a + i * c, b + i * c);
            if (r) return r;
        }
        return 0;
    }
    }
    return 0;
}

// One level's node boxes, indexed by the node's word offset in the level,
// in the narrowest unsigned type that holds the level's local coordinates
// (a node of 8 voxels needs 6 bytes, not 48): the level above the leaves
// has about one entry per 16-bit word of the whole DAG.
class LevelBoxes {
public:
    LevelBoxes(uint64_t words, int64_t nodeSize)
        : width_(nodeSize <= 256 ? 1 : nodeSize <= 65536 ? 2 : nodeSize <= (int64_t(1) << 32) ? 4 : 8), bytes_(size_t(words) * 6 * width_) {}
    LocalBox get(uint64_t at) const {
        LocalBox b;
        const uint8_t* p = bytes_.data() + at * 6 * width_;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = read(p + a * width_);
            b.hi[a] = read(p + (3 + a) * width_);
        }
        // Stored as lo = hi + 1 on x when empty (a node is never empty but
        // for the unset words between node starts).
        b.any = b.lo[0] <= b.hi[0];
        return b;
    }
    void set(uint64_t at, const LocalBox& b) {
        uint8_t* p = bytes_.data() + at * 6 * width_;
        for (int a = 0; a < 3; ++a) {
            write(p + a * width_, b.any ? b.lo[a] : (a == 0 ? 1 : 0));
            write(p + (3 + a) * width_, b.any ? b.hi[a] : 0);
        }
    }

private:
    int64_t read(const uint8_t* p) const {
        uint64_t v = 0;
        std::memcpy(&v, p, width_);  // little-endian low bytes
        return int64_t(v);
    }
    void write(uint8_t* p, int64_t v) const {
        const uint64_t u = uint64_t(v);
        std::memcpy(p, &u, width_);
    }
    unsigned width_;
    std::vector<uint8_t> bytes_;
};

} // namespace

std::optional<IndexBox> dagBounds(const encoding::CompactDag& dag) {
    if (dag.empty()) return std::nullopt;
    const size_t levels = dag.innerLevelCount();
    std::optional<LevelBoxes> below;
    LocalBox root;
    for (size_t i = levels; i-- > 0;) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        const int64_t size = int64_t(1) << (dag.log2Size - i), half = size / 2;
        const bool toLeaves = i + 1 == levels;
        LevelBoxes here(end - begin, size);
        for (uint64_t pos = begin; pos < end; pos += encoding::nodeWordCount(dag.inner[pos], dag.offsetWords[i])) {
            const uint16_t header = dag.inner[pos];
            LocalBox box;
            if (header == 0) {  // solid node
                box = LocalBox{{0, 0, 0}, {size - 1, size - 1, size - 1}, true};
            } else {
                for (unsigned j = 0; j < 8; ++j) {
                    if (((header >> (2 * j)) & 3u) == 0) continue;
                    const encoding::ChildPointer p = encoding::readChild(dag.inner, pos, j, dag.offsetWords[i]);
                    const std::array<int64_t, 3> at{(j & 1u) ? half : 0, (j & 2u) ? half : 0, (j & 4u) ? half : 0};
                    const LocalBox child = toLeaves ? brickBox(dag.leaves[p.offset]) : below->get(p.offset);
                    box.merge(child.placed(p.reflection, half, at));
                }
            }
            if (i == 0) root = box;  // the root level holds one node, at word 0
            else here.set(pos - begin, box);
            if (i == 0) break;
        }
        below.emplace(std::move(here));
    }
    const LocalBox placed = root.placed(dag.rootReflection, int64_t(1) << dag.log2Size, dag.origin);
    if (!placed.any) return std::nullopt;
    return IndexBox{placed.lo, placed.hi};
}

void ValueRange::add(ValueType type, std::span<const uint8_t> values) {
    const unsigned vs = valueSize(type);
    if (!vs) return;
    for (size_t at = 0; at + vs <= values.size(); at += vs) {
        const uint8_t* v = values.data() + at;
        if (min.empty()) {
            min.assign(v, v + vs);
            max.assign(v, v + vs);
            continue;
        }
        if (compareValues(type, v, min.data()) < 0) std::memcpy(min.data(), v, vs);
        if (compareValues(type, max.data(), v) < 0) std::memcpy(max.data(), v, vs);
    }
}

GridSummary summarizeGrid(const EncodedGrid& grid) {
    GridSummary s;
    s.activeVoxels = grid.activeVoxels;
    s.solidNodes = encoding::decodedSize(grid.dag).emittedTiles;
    s.indexBox = dagBounds(grid.dag);
    const ValueType type = grid.record.valueType;
    const unsigned vs = valueSize(type);
    if (!vs || grid.dag.empty()) return s;
    if (!grid.attributes.empty()) {
        s.activeRange.add(type, grid.attributes);
        return s;
    }
    const attributes::ValueWindowsPayload& windows = grid.valueWindows;
    if (windows.empty()) {  // a scene read with its palette channel only
        s.activeRange.add(type, grid.values.decodeAll());
        return s;
    }
    const std::vector<uint8_t> spilled = windows.file ? windows.load() : std::vector<uint8_t>{};
    const std::span<const uint8_t> bytes = windows.file ? std::span<const uint8_t>(spilled) : std::span<const uint8_t>(windows.bytes);
    const std::string what = "grid '" + grid.record.name + "' value windows";
    if (!windows.predicted) {
        // Every value of a window is one of its materials or stored directly:
        // their range is the window's, and no index is unpacked.
        const attributes::WindowDirectory dir = attributes::readValueWindowDirectory(bytes, what);
        for (size_t k = 0; k < dir.windows.size(); ++k) {
            const attributes::PaletteChannel window = attributes::decodeValueWindow(bytes, dir, k, what);
            s.activeRange.add(type, window.materials);
            s.activeRange.add(type, window.direct);
        }
        return s;
    }
    const std::vector<uint64_t> layout = encoding::attributeLayout(grid.dag);
    attributes::WindowCursor cursor(bytes, true, vs, layout, what);
    constexpr uint64_t kChunk = uint64_t(1) << 16;
    std::vector<uint8_t> chunk;
    for (uint64_t done = 0; done < cursor.entries();) {
        const uint64_t n = std::min(kChunk, cursor.entries() - done);
        chunk.resize(size_t(n * vs));
        cursor.read(n, chunk.data());
        s.activeRange.add(type, chunk);
        done += n;
    }
    return s;
}

std::vector<double> valueNumbers(ValueType type, std::span<const uint8_t> value) {
    if (value.size() < valueSize(type)) throw Error("internal error: value too short");
    const std::array<double, 3> d = valueAsDoubles(type, value.data());
    return std::vector<double>(d.begin(), d.begin() + valueComponents(type));
}

std::string formatValue(ValueType type, std::span<const uint8_t> value) {
    if (type == ValueType::Int64) {  // exact, past 2^53
        int64_t v = 0;
        std::memcpy(&v, value.data(), std::min(value.size(), sizeof(v)));
        return std::to_string(v);
    }
    const std::vector<double> n = valueNumbers(type, value);
    if (n.empty()) return "-";
    if (n.size() == 1) return fmt::format("{:.6g}", n[0]);
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", n[0], n[1], n[2]);
}

} // namespace vdbdag::format
