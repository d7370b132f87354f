// Finds and loads libvdbdag_images.so (image_module/ImageModule.h) the
// first time a picture is written, so that commands that write none never
// load OpenImageIO. Looked for beside the running program (the build
// folder) and in ../lib/vdbdag from it (an installed tree).
#pragma once
#include "vdb_bridge/image_module/ImageModule.h"

namespace vdbdag::bridge::detail {

struct ImageModule {
    image_module::WriteFrameFn* writeFrame = nullptr;
    image_module::WritePlotFn* writePlot = nullptr;
};

// Loaded once per process; an Error naming `forPath` and where the module
// was looked for if it cannot be loaded.
const ImageModule& imageModule(const std::string& forPath);

} // namespace vdbdag::bridge::detail
