// Voxel counting for GridTopology (tiles counted as their voxels).
#include "src/volume/GridTopology.h"

#include <bit>
#include <limits>

namespace vdbdag {

uint64_t GridTopology::activeVoxelCount() const {
    uint64_t count = 0;
    for (const Brick& b : bricks) count += uint64_t(std::popcount(b.mask));
    for (const Tile& t : tiles) {
        if (3u * t.log2Size >= 64) return std::numeric_limits<uint64_t>::max();
        const uint64_t voxels = uint64_t(1) << (3u * t.log2Size);
        if (count > std::numeric_limits<uint64_t>::max() - voxels) return std::numeric_limits<uint64_t>::max();
        count += voxels;
    }
    return count;
}

} // namespace vdbdag
