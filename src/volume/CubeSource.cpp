// See CubeSource.h.
#include "src/volume/CubeSource.h"

namespace vdbdag {

void selectLargeTiles(const GridTopology& all, const LayerValues& values, unsigned valueSize, unsigned log2, GridTopology& tiles,
                      LayerValues& tileValues) {
    tiles = {};
    tileValues = {};
    for (size_t i = 0; i < all.tiles.size(); ++i) {
        if (all.tiles[i].log2Size <= log2) continue;
        tiles.tiles.push_back(all.tiles[i]);
        if (valueSize)
            tileValues.tiles.insert(tileValues.tiles.end(), values.tiles.begin() + long(i * valueSize), values.tiles.begin() + long((i + 1) * valueSize));
    }
}

} // namespace vdbdag
