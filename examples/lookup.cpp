// vdbdag_lookup: point lookups in a .ssvdag through the public reader.
//
//   vdbdag_lookup FILE              lists the grids: name, type, class,
//                                   active voxels, index bounding box
//   vdbdag_lookup FILE GRID < IJK   for each line "i j k" of stdin prints
//                                   "A HEX": A is 1 if the voxel is active,
//                                   HEX its value's bytes in memory order
//                                   ("-" for a mask grid)
#include <vdbdag/vdbdag.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 2 && argc != 3) {
        std::cerr << "usage: vdbdag_lookup FILE [GRID] < coordinates\n";
        return 2;
    }
    try {
        const vdbdag::File file = vdbdag::File::open(argv[1]);
        if (argc == 2) {
            for (size_t g = 0; g < file.gridCount(); ++g) {
                const vdbdag::Grid& grid = file.grid(g);
                const vdbdag::IndexBBox box = grid.indexBBox();
                std::printf("%zu '%s' %s %s, %llu active voxels, bbox (%lld,%lld,%lld)-(%lld,%lld,%lld)\n", g, grid.name().c_str(),
                            grid.valueType().c_str(), grid.gridClass().c_str(), (unsigned long long)grid.activeVoxelCount(),
                            (long long)box.min[0], (long long)box.min[1], (long long)box.min[2], (long long)box.max[0], (long long)box.max[1],
                            (long long)box.max[2]);
            }
            return 0;
        }
        const vdbdag::Grid& grid = file.grid(std::string(argv[2]));
        vdbdag::Accessor accessor = grid.accessor();
        std::vector<unsigned char> value(grid.valueSize());
        std::string out;
        long long i, j, k;
        static const char* kHex = "0123456789abcdef";
        while (std::cin >> i >> j >> k) {
            out += accessor.isActive(i, j, k) ? "1 " : "0 ";
            if (value.empty()) {
                out += '-';
            } else {
                accessor.valueBytes(i, j, k, value.data());
                for (unsigned char b : value) {
                    out += kHex[b >> 4];
                    out += kHex[b & 15];
                }
            }
            out += '\n';
        }
        std::fwrite(out.data(), 1, out.size(), stdout);
        return 0;
    } catch (const vdbdag::Error& e) {
        std::cerr << "vdbdag_lookup: " << e.what() << "\n";
        return 1;
    }
}
