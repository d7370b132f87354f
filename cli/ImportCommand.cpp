// `vdbdag import IN.nrrd|IN.nhdr|IN.mhd|IN.mha|IN.raw -o OUT.vdb`: a dense
// scan as an OpenVDB grid (all samples active, or thresholded), written by
// OpenVDB (atomically).
#include <chrono>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/EncodeReportJson.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "cli/RunContext.h"
#include "cli/DenseInputOptions.h"
#include "cli/ReadLimitOptions.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/VdbExport.h"

namespace vdbdag::cli {

void addImportCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::vector<std::string> inputs;
        std::string input, output;
        bool json = false, force = false;
        DenseInputOptions dense;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("import", "Convert a dense scan (.raw, .nrrd, .nhdr, .mhd, .mha, .nii, or one DICOM series: a folder, .dcm or DICOMDIR with --series) into a .vdb grid");
    cmd->add_option("input", opt->inputs, "input volume, or DICOM input (folders, .dcm files, DICOMDIRs: several are read as one set)")->required();
    cmd->add_option("-o,--output", opt->output, "output .vdb file")->required();
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the summary as JSON");
    opt->dense.addTo(*cmd);
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        app::DenseInputs dense = opt->dense.inputs();
        opt->input = dense.takeInputs(opt->inputs);
        setActivity(opt->input, "importing");
        const auto start = std::chrono::steady_clock::now();
        if (bridge::denseFormatOf(opt->input) == bridge::DenseFormat::None)
            throw Error(opt->input + ": not a dense volume (expected .raw, .nrrd, .nhdr, .mhd, .mha, .nii, .nii.gz, .hdr or DICOM)");
        checkOutputPath(opt->output, app::denseInputFiles(opt->input, dense), {{".vdb"}, "import", opt->force});
        bridge::DenseImportOptions denseOptions = dense.resolve(opt->input);
        denseOptions.limits = opt->limits.limits(1);  // the grid record, then the OpenVDB grid written
        const bridge::DenseImportResult imported = bridge::importDense(opt->input, denseOptions);
        {
            Progress progress("import: writing " + opt->output, 1);
            bridge::exportVdb(imported.volume, opt->output);
            progress.finish();
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const GridRecord& g = imported.volume.grids.front();
        const auto& d = imported.source.dims;
        nlohmann::json report{{"input", opt->input},
                              {"output", opt->output},
                              {"dims", {d[0], d[1], d[2]}},
                              {"sample_type", bridge::sampleTypeName(imported.source.type)},
                              {"grid", g.name},
                              {"value_type", valueTypeName(g.valueType)},
                              {"active_voxels", g.topology.activeVoxelCount()},
                              {"seconds", seconds},
                              {"threshold", app::thresholdJson(imported.threshold)}};
        if (opt->json) {
            printJson(report);
        } else {
            fmt::print("{}: {}x{}x{} {} samples -> {} grid '{}', {} active voxels in {:.2f} s\n", opt->output, d[0], d[1], d[2],
                       bridge::sampleTypeName(imported.source.type), valueTypeName(g.valueType), g.name, g.topology.activeVoxelCount(), seconds);
            fmt::print("{}", thresholdText(imported.threshold));
        }
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
