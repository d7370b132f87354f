// See PlotWriter.h: the plot is drawn and written by libvdbdag_images.so.
#include "vdb_bridge/PlotWriter.h"

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "vdb_bridge/detail/ImageModuleLoader.h"

namespace vdbdag::bridge {

void writeScatterPlot(const std::string& path, const std::vector<PlotSeries>& series, const PlotSpec& spec) {
    const detail::ImageModule& module = detail::imageModule(path);
    writeViaTemporary(path, [&](const std::string& temp) {
        std::string error;
        if (!module.writePlot(temp.c_str(), series, spec, error)) throw Error(path + ": " + error);
    }, ".png");
}

} // namespace vdbdag::bridge
