// Backend selection for rendering; see RenderBackend.h.
#include "cli/RenderBackend.h"

#include "src/util/Error.h"

namespace vdbdag::cli {
namespace {

class CpuBackend final : public RenderBackend {
public:
    std::string name() const override { return "cpu"; }
    trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                        trace::RenderStats& stats) override {
        return trace::renderCpu(grid, camera, options, &stats);
    }
};

} // namespace

std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& kind, int device) {
    if (kind == "vulkan") throw Error("the Vulkan backend is not available in this build yet: use --backend cpu");
    (void)device;
    return std::make_unique<CpuBackend>();
}

} // namespace vdbdag::cli
