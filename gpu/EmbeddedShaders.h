// The SPIR-V of every gpu/shaders/*.comp, compiled at build time by glslc
// (--target-env=vulkan1.2 -O) and embedded in the binary as uint32_t words
// (cmake/EmbedSpirv.cmake). Looked up by the shader file's stem.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace vdbdag::gpu {

// The words of gpu/shaders/<name>.comp; throws vdbdag::Error listing the
// embedded shaders when there is no such shader.
std::span<const uint32_t> embeddedShader(std::string_view name);

std::vector<std::string_view> embeddedShaderNames();

} // namespace vdbdag::gpu
