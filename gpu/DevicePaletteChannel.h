// A palette channel (src/attributes/PaletteChannel.h) uploaded for a shader:
// its five sections (materials, palettes, block directory, packed indices,
// direct values) as DeviceArrays, and the struct the shader reads them
// through (PaletteChannelGpu, the std430 layout of `struct PaletteChannel`
// in gpu/shaders/palette_channel.glsl). The tracer uploads one for the
// values and one for the ONV normal codes.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/DeviceArray.h"
#include "src/attributes/PaletteChannel.h"

namespace vdbdag::gpu {

// Same layout as GLSL `struct PaletteChannel` (std430, 144 bytes).
struct PaletteChannelGpu {
    DeviceArrayRef materials, palettes, blocks, indexBits, direct;
    uint64_t entryCount = 0, blockCount = 0;
    uint32_t valueSize = 0, pad = 0;
};
static_assert(sizeof(PaletteChannelGpu) == 144, "must match gpu/shaders/palette_channel.glsl");

class DevicePaletteChannel {
public:
    // Uploads `channel`; null uploads an empty channel (every array a small
    // zero buffer, so every address is valid; entryCount 0). `label` names
    // the channel in out-of-memory errors.
    DevicePaletteChannel(VulkanContext& context, const attributes::PaletteChannel* channel, const std::string& label,
                         DeviceArrayOptions options = {});

    const PaletteChannelGpu& ref() const { return ref_; }

private:
    std::vector<DeviceArray> arrays_;
    PaletteChannelGpu ref_;
};

} // namespace vdbdag::gpu
