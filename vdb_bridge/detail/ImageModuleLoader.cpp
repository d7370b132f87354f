// See ImageModuleLoader.h.
#include "vdb_bridge/detail/ImageModuleLoader.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

#include "src/util/Error.h"

namespace vdbdag::bridge::detail {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> candidates() {
    std::error_code ec;
    const fs::path program = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return {};
    const fs::path folder = program.parent_path();
    return {folder / image_module::kModuleFile, folder.parent_path() / "lib" / "vdbdag" / image_module::kModuleFile};
}

struct Loaded {
    ImageModule module;
    std::string problem;  // empty when loaded
};

Loaded load() {
    Loaded result;
    std::string tried;
    for (const fs::path& path : candidates()) {
        tried += (tried.empty() ? "" : ", ") + path.string();
        if (!fs::exists(path)) continue;
        // Never closed: OpenImageIO's own static data lives until exit.
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            result.problem = std::string("cannot load ") + dlerror();
            return result;
        }
        result.module.writeFrame = reinterpret_cast<image_module::WriteFrameFn*>(dlsym(handle, image_module::kWriteFrame));
        result.module.writePlot = reinterpret_cast<image_module::WritePlotFn*>(dlsym(handle, image_module::kWritePlot));
        if (!result.module.writeFrame || !result.module.writePlot) result.problem = path.string() + " lacks the image writers (a different build?)";
        return result;
    }
    result.problem = std::string("cannot write pictures: ") + image_module::kModuleFile + " is not installed (looked for " + tried + ")";
    return result;
}

} // namespace

const ImageModule& imageModule(const std::string& forPath) {
    static const Loaded loaded = load();
    if (!loaded.problem.empty()) throw Error(forPath + ": " + loaded.problem);
    return loaded.module;
}

} // namespace vdbdag::bridge::detail
