// Lookup in the generated table of embedded SPIR-V modules (the table is
// written by CMakeLists.txt into the build tree: EmbeddedShaderTable.cpp).
#include "gpu/EmbeddedShaders.h"

#include <string>
#include <utility>

#include <fmt/core.h>

#include "src/util/Error.h"

namespace vdbdag::gpu {

namespace embedded {
// Ends with an entry whose name is empty.
extern const std::pair<std::string_view, std::span<const uint32_t>> kShaderTable[];
} // namespace embedded

std::vector<std::string_view> embeddedShaderNames() {
    std::vector<std::string_view> names;
    for (const auto* e = embedded::kShaderTable; !e->first.empty(); ++e) names.push_back(e->first);
    return names;
}

std::span<const uint32_t> embeddedShader(std::string_view name) {
    for (const auto* e = embedded::kShaderTable; !e->first.empty(); ++e)
        if (e->first == name) return e->second;
    std::string known;
    for (std::string_view n : embeddedShaderNames()) known += fmt::format("{}{}", known.empty() ? "" : ", ", n);
    throw Error(fmt::format("no embedded shader named '{}' (embedded: {})", name, known));
}

} // namespace vdbdag::gpu
