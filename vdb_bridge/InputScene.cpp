// See InputScene.h.
#include "vdb_bridge/InputScene.h"

#include <cstring>
#include <filesystem>
#include <fstream>

#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::bridge {

InputKind inputKindOf(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {  // only a regular file is opened to look (never a FIFO)
        unsigned char head[8] = {};
        std::ifstream in(path, std::ios::binary);
        in.read(reinterpret_cast<char*>(head), sizeof head);
        const size_t n = size_t(in.gcount());
        if (n >= 8 && std::memcmp(head, "\x89SSVDAG\n", 8) == 0) return InputKind::Ssvdag;
        if (n >= 4 && std::memcmp(head, "\x20\x42\x44\x56", 4) == 0) return InputKind::Vdb;  // OpenVDB's magic, little-endian
        if (n >= 7 && std::memcmp(head, "NanoVDB", 7) == 0) return InputKind::NanoVdb;
    }
    if (denseFormatOf(path) != DenseFormat::None) return InputKind::Dense;
    if (isNanoVdbPath(path)) return InputKind::NanoVdb;
    return InputKind::Ssvdag;
}

format::SsvdagScene sceneOfInput(const std::string& path, const format::ReadOptions& readOptions) {
    Volume volume;
    switch (inputKindOf(path)) {
        case InputKind::Ssvdag: return format::readSceneFile(path, readOptions);
        case InputKind::NanoVdb: volume = importNanoVdb(path).volume; break;
        case InputKind::Vdb: volume = importVdb(path).volume; break;
        case InputKind::Dense: {
            DenseImportOptions options;
            options.showProgress = false;
            volume = importDense(path, options).volume;
            break;
        }
    }
    return pipeline::encodeVolumeReleasing(volume);
}

} // namespace vdbdag::bridge
