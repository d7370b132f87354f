// vdbdag: the public reader of .ssvdag files (docs/FORMAT.md).
//
//   #include <vdbdag/vdbdag.h>
//   vdbdag::File file = vdbdag::File::open("bunny.ssvdag");  // throws vdbdag::Error
//   const vdbdag::Grid& g = file.grid(0);                      // or file.grid("ls_bunny")
//   vdbdag::Accessor a = g.accessor();                         // one per thread
//   if (a.isActive(i, j, k)) float v = a.value<float>(i, j, k);
//
// Opening a file reads its section table and its grids' headers; a grid's
// DAGs and value payloads are read the first time the grid is walked (an
// Accessor, forEachActive, a sample), and each value channel is decoded the
// first time a value of it is asked for. (A file written before Summary
// sections, docs/FORMAT.md 10.1, is read whole on open.) The limits a file
// is opened with are weighed on open against what its table and headers
// claim, and again as each grid is read. A
// File, its Grids and their Accessors are used from any number of threads
// (an Accessor from one at a time); Grids and Accessors refer to the File
// they came from, which must outlive them.
//
// Values are the exact bits the file stores: an active voxel's value; an
// inactive voxel's own value where the grid stores one (OpenVDB's inactive
// values that differ from the background); the background elsewhere. Value
// types and the C++ type value<T> takes:
//   "float" float, "double" double, "int32" int32_t, "int64" int64_t,
//   "bool" bool, "mask" bool (the active state), "vec3s" std::array<float, 3>,
//   "vec3d" std::array<double, 3>, "vec3i" std::array<int32_t, 3>.
//
// Built with CMake: find_package(vdbdag CONFIG) and link vdbdag::vdbdag; or
// pkg-config vdbdag. The library depends on the C++ standard library, zstd
// and xxHash only.
#pragma once
#include <array>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <vdbdag/Error.h>

namespace vdbdag {

// The library's version, and the newest .ssvdag format version it reads
// (every older one too).
inline constexpr int kVersionMajor = 0, kVersionMinor = 1, kVersionPatch = 0;
VDBDAG_API int readableFormatVersion();

// An inclusive box of index coordinates, as OpenVDB's CoordBBox; empty()
// when min > max (a grid with no active voxels).
struct IndexBBox {
    std::array<int64_t, 3> min{0, 0, 0}, max{-1, -1, -1};
    bool empty() const { return min[0] > max[0] || min[1] > max[1] || min[2] > max[2]; }
};

namespace detail {
struct GridData;
struct FileData;

// The value type (the table above, in the file's order) whose C++ type T
// is; -1 for any other type (a user's Vec3f, say), which value<T> takes by
// its size as the value's raw bits.
template <typename T>
constexpr int valueTypeCodeOf() {
    if constexpr (std::is_same_v<T, float>) return 0;
    else if constexpr (std::is_same_v<T, double>) return 1;
    else if constexpr (std::is_same_v<T, int32_t>) return 2;
    else if constexpr (std::is_same_v<T, int64_t>) return 3;
    else if constexpr (std::is_same_v<T, bool>) return 4;
    else if constexpr (std::is_same_v<T, std::array<float, 3>>) return 6;
    else if constexpr (std::is_same_v<T, std::array<double, 3>>) return 7;
    else if constexpr (std::is_same_v<T, std::array<int32_t, 3>>) return 8;
    else return -1;
}

// Whether a T of value type `code` (valueTypeCodeOf) and `size` bytes may
// be read from `grid`: the grid's own type, or any other type of the
// value's size. refuseValueType throws the vdbdag::Error that says why not.
VDBDAG_API bool valueTypeFits(const GridData* grid, int code, size_t size) noexcept;
[[noreturn]] VDBDAG_API void refuseValueType(const GridData* grid, int code, size_t size);
inline void checkValueType(const GridData* grid, int code, size_t size) {
    if (!valueTypeFits(grid, code, size)) refuseValueType(grid, code, size);
}
} // namespace detail

// Random access to one grid's voxels. Cheap to make (make one per thread);
// it remembers the path to the last voxel it found, per layer, and starts
// the next walk from the deepest node that still holds the new voxel, as
// NanoVDB's ReadAccessor does, so coherent lookups cost a few steps.
// A 4^3 brick missed again, or next to the brick of the last miss, has its
// 64 values and active states copied into a cache of 1024 bricks
// (BrickCache), so a sweep through a box of up to 128 voxels a side finds
// each voxel there with a compare and a load (docs/LIBRARY.md). The cache
// is made when the first brick is copied: 32 KB, plus 64 KB per byte of
// the value type (288 KB in all for float).
class VDBDAG_API Accessor {
public:
    bool isActive(int64_t i, int64_t j, int64_t k);
    // The value's bytes (valueSize() of them; none for a mask grid).
    void valueBytes(int64_t i, int64_t j, int64_t k, void* out);
    // The value as T: the C++ type of the grid's value type (the table
    // above), or a type of another name with the value's size (its raw
    // bits, e.g. openvdb::Vec3f for vec3s). Throws vdbdag::Error otherwise:
    // value<float> of an int32 grid is refused, not the int's bits.
    template <typename T>
    T value(int64_t i, int64_t j, int64_t k) {
        static_assert(std::is_trivially_copyable_v<T>);
        if constexpr (std::is_same_v<T, bool>) {
            if (maskGrid()) return isActive(i, j, k);
        }
        // The calls below that may fail do not throw (the failure is thrown
        // by a call that does not return): a caller's loop around value<T>
        // then keeps its sums in registers, which a call that may unwind
        // through the accessor's destructor keeps GCC from doing.
        constexpr int64_t asked = int64_t(detail::valueTypeCodeOf<T>()) << 32 | int64_t(sizeof(T));
        if (checkedType_ != asked) [[unlikely]] {
            if (!detail::valueTypeFits(grid_, detail::valueTypeCodeOf<T>(), sizeof(T))) detail::refuseValueType(grid_, detail::valueTypeCodeOf<T>(), sizeof(T));
            checkedType_ = asked;
        }
        T out;
        if (const uint8_t* cached = cachedValue<sizeof(T)>(i, j, k)) [[likely]] {
            std::memcpy(&out, cached, sizeof(T));
            return out;
        }
        if (!valueBytesOrFailure(i, j, k, &out)) rethrowFailure();
        return out;
    }
    unsigned valueSize() const;

    // Where a walk left off, per layer (internal; see Accessor.cpp).
    struct Path {
        static constexpr unsigned kMaxDepth = 64;
        struct Node {
            uint64_t pos = 0, base = 0;  // header word in the DAG's inner words, first attribute entry
            unsigned mirror = 0;
        };
        Node nodes[kMaxDepth];
        std::array<int64_t, 3> key{};  // the voxel of the last walk, relative to the root
        unsigned depth = 0;             // nodes[0 .. depth) hold the last walk's path
        size_t paletteHint = 0;         // palette block of the last value
        // The 4^3 leaf that the last walk ended in, if it ended in one: a
        // voxel of the same brick is answered from it without a walk.
        struct Leaf {
            uint64_t stored = 0, base = 0;  // its stored bits, the entry of its first set bit
            unsigned mirror = 0;            // the mirror mask it is read through
            bool valid = false;
        } leaf;
        // Or the cube of 2^log2 voxels that it ended in, where every voxel
        // has the same answer: a solid node's (one entry) or an empty
        // child's (none). log2 = 64: none.
        struct Uniform {
            unsigned log2 = 64;
            bool found = false;
            uint64_t entry = 0;
        } uniform;
        // The last value read, by entry: a run of voxels of one entry (a
        // solid node, a tile) reads the channel once.
        uint64_t valueEntry = ~uint64_t(0);
        uint8_t value[24] = {};  // the largest value: vec3d
    };

    // Whole 4^3 bricks (internal; see Accessor.cpp): the brick of world
    // voxels (4 bx .. 4 bx + 3, ...) goes in slot slotOf(bx, by, bz). A
    // brick is copied when a lookup the cache misses falls in the brick of
    // the last miss or next to it (a sweep), so scattered lookups copy
    // nothing.
    struct BrickCache {
        static constexpr size_t kSlots = 1024;
        // Injective on every 32 x 32 square of bricks in an axis-aligned
        // plane, whichever two axes it spans: a sweep with any axis outermost
        // keeps each brick of a 128-voxel slab until the next slab reuses it.
        static size_t slotOf(int64_t bx, int64_t by, int64_t bz) { return size_t((bx ^ by) & 31) | size_t((bx ^ bz) & 31) << 5; }
        struct Key {
            int64_t x = INT64_MIN, y = 0, z = 0;  // INT64_MIN: none (no brick's x)
            bool is(int64_t bx, int64_t by, int64_t bz) const { return ((x ^ bx) | (y ^ by) | (z ^ bz)) == 0; }
        };
        std::vector<Key> filled;      // kSlots once a brick is filled: the brick each slot holds
        Key lastMiss;                 // the brick of the last lookup the cache did not answer
        std::vector<uint64_t> active; // per slot, bit x + 4 y + 16 z: the voxel is active
        std::vector<uint8_t> values;  // kSlots x 64 values, voxel x + 4 y + 16 z
        bool usable = true;           // false where a layer's bricks are not on the 4-voxel grid
    };

private:
    friend class Grid;
    explicit Accessor(const detail::GridData* grid);
    bool maskGrid() const;
    // The slot holding voxel (i, j, k)'s brick, or -1; the voxel's index in it.
    int64_t filledSlot(int64_t i, int64_t j, int64_t k) const {
        if (cache_.filled.empty()) return -1;
        const int64_t bx = i >> 2, by = j >> 2, bz = k >> 2;
        const size_t s = BrickCache::slotOf(bx, by, bz);
        return cache_.filled[s].is(bx, by, bz) ? int64_t(s) : -1;
    }
    static size_t voxelInBrick(int64_t i, int64_t j, int64_t k) { return size_t((i & 3) | (j & 3) << 2 | (k & 3) << 4); }
    // The cached value of voxel (i, j, k) (its N bytes), or null.
    template <size_t N>
    const uint8_t* cachedValue(int64_t i, int64_t j, int64_t k) const {
        const int64_t s = filledSlot(i, j, k);
        return s < 0 ? nullptr : cache_.values.data() + (size_t(s) * 64 + voxelInBrick(i, j, k)) * N;
    }
    // valueBytes, with what it throws kept in failure_ (false) for
    // rethrowFailure to throw.
    bool valueBytesOrFailure(int64_t i, int64_t j, int64_t k, void* out) noexcept;
    [[noreturn]] void rethrowFailure();
    // The slot of voxel (i, j, k)'s brick if it is filled (found, or filled
    // now, next to the last miss); else -1.
    int64_t brickSlot(int64_t i, int64_t j, int64_t k);
    void fillSlot(size_t s, int64_t bx, int64_t by, int64_t bz);
    const detail::GridData* grid_;
    unsigned valueSize_ = 0;
    int64_t checkedType_ = -1;  // value<T>'s type (code << 32 | size), once checked
    std::exception_ptr failure_;
    Path active_, inactive_;
    BrickCache cache_;
};

class VDBDAG_API Grid {
public:
    const std::string& name() const;
    const std::string& gridClass() const;   // "level set", "fog volume", "staggered", "unknown"
    std::string valueType() const;          // "float", "double", "int32", "int64", "bool", "mask", "vec3s", "vec3d", "vec3i"
    unsigned valueSize() const;             // bytes per value (bool 1, mask 0)
    uint64_t activeVoxelCount() const;      // tiles counted as their voxels
    uint64_t inactiveVoxelCount() const;    // inactive voxels whose value is stored (not the background)
    IndexBBox indexBBox() const;            // of the active voxels
    std::array<double, 16> indexToWorld() const;  // 4x4 row-major, as OpenVDB's Mat4d: world = [i j k 1] * M
    // The background value's bytes (valueSize() of them).
    void backgroundBytes(void* out) const;
    template <typename T>
    T background() const {
        static_assert(std::is_trivially_copyable_v<T>);
        detail::checkValueType(data_, detail::valueTypeCodeOf<T>(), sizeof(T));
        T out;
        backgroundBytes(&out);
        return out;
    }
    Accessor accessor() const { return Accessor(data_); }
    // The values of `box`'s voxels every `stride` voxels along each axis,
    // from box.min (stride 1: every voxel, as OpenVDB's copyToDense; stride
    // 2^L: the point samples of a level of detail L), written with i
    // fastest, then j, then k: a VTK image's point order, numpy's [k][j][i].
    // A value is what Accessor::valueBytes answers; a mask grid writes one
    // byte per voxel, 1 where it is active. `out` holds
    // sampleCount(box, stride) * max(valueSize(), 1) bytes. The accessor is
    // made here, so disjoint boxes may be read from several threads.
    void sampleBox(const IndexBBox& box, uint64_t stride, void* out) const;
    // The same samples' active states, one byte each (1: active).
    void sampleActive(const IndexBBox& box, uint64_t stride, uint8_t* out) const;
    // Every active voxel and tile of the grid that overlaps `box`:
    // visit(corner, log2, value) with the cube's minimum corner, log2 of its
    // edge (0: a voxel; more: a tile, or a cube of voxels that the DAG stores
    // as one value) and the value's bytes (valueSize() of them; nullptr for a
    // mask grid). A cube is given whole where it sticks out of the box. The
    // walk stops when visit returns false.
    using ActiveVisitor = std::function<bool(const std::array<int64_t, 3>& corner, unsigned log2, const void* value)>;
    void forEachActive(const IndexBBox& box, const ActiveVisitor& visit) const;

private:
    friend struct detail::FileData;
    explicit Grid(const detail::GridData* data) : data_(data) {}
    const detail::GridData* data_;
};

// Samples per axis of `box` read every `stride` voxels ((max - min) / stride
// + 1; 0 on each axis of an empty box), and their product. Throws
// vdbdag::Error for a stride of 0 or a count past 2^62.
VDBDAG_API std::array<uint64_t, 3> sampleDims(const IndexBBox& box, uint64_t stride);
VDBDAG_API uint64_t sampleCount(const IndexBBox& box, uint64_t stride);

// What a file may make the reader hold before open() refuses it: a forged
// file of a few kilobytes can claim sections of gigabytes or a DAG standing
// for 2^60 voxels. Both are weighed before anything is inflated or decoded.
struct OpenLimits {
    // Entries of any one layer of a grid (each voxel of a brick; a tile
    // once). The default, 2^36, is a 4096^3 dense block.
    uint64_t maxVoxels = uint64_t(1) << 36;
    // Bytes of the inflated sections and decoded values; 0: three quarters
    // of the physical memory, or of the process's memory limit when lower.
    uint64_t maxMemory = 0;
};

// A frame of a sequence file (the frames of a cache in one file): its
// number (smoke.0042.vdb: 42) and its grids, grid(firstGrid) on.
struct Frame {
    int64_t number = 0;
    size_t firstGrid = 0, gridCount = 0;
};

class VDBDAG_API File {
public:
    // Maps the file and checks it (format version, checksums, every DAG)
    // within `limits`; throws vdbdag::Error with a one-line message naming
    // the file (and the limit a file would exceed).
    static File open(const std::string& path, const OpenLimits& limits);
    static File open(const std::string& path);  // within the default OpenLimits
    size_t gridCount() const;
    const Grid& grid(size_t index) const;
    const Grid& grid(const std::string& name) const;  // the first grid of that name
    // The frames, in order: a sequence file's, or for a file of one volume
    // one frame numbered 0 holding every grid.
    const std::vector<Frame>& frames() const;
    bool isSequence() const;  // the file holds frames (a Frames section)
    // The grid of that name in the frame of that number; throws
    // vdbdag::Error naming the file when there is none.
    const Grid& grid(const std::string& name, int64_t frame) const;
    uint32_t formatVersion() const;                    // of this file
    const std::string& path() const;

private:
    explicit File(std::shared_ptr<const detail::FileData> data) : data_(std::move(data)) {}
    std::shared_ptr<const detail::FileData> data_;
};

} // namespace vdbdag
