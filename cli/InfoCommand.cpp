// `vdbdag info FILE... [--json]`: parses the request, describes each input
// through app::describeInput or app::describeDicom (app/InputReport.h) and
// prints the text or the JSON report.
#include <fmt/core.h>

#include "app/InputReport.h"
#include "cli/Commands.h"
#include "app/DenseInputs.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/util/Error.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::cli {

void addInfoCommand(CLI::App& app, int& exitCode) {
    struct InfoOptions {
        std::vector<std::string> inputs;
        bool json = false;
        app::InfoRequest request;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "Print per-grid DAG statistics and section sizes of .ssvdag, .vdb or .nvdb files (or a scan's header, or the series of DICOM input)");
    cmd->add_option("input", opt->inputs, ".ssvdag, .vdb or .nvdb files, scans, or DICOM input (folders, .dcm files, DICOMDIRs: several are read as one set)")->required();
    cmd->add_flag("--json", opt->json, "print JSON (an array for several inputs)");
    cmd->add_flag("--no-symmetry", opt->request.noSymmetry, "for .vdb input: report the plain SVDAG encoding");
    cmd->add_flag("--values", opt->request.values,
                  "for .ssvdag input: also each value channel's statistics (entries, distinct values, palette blocks) and the size traceable in "
                  "memory; decodes every value (slower)");
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        exitCode = 0;
        if (bridge::denseFormatOf(opt->inputs.front()) == bridge::DenseFormat::Dicom) {
            app::DenseInputs dicomInputs;
            const std::string input = dicomInputs.takeInputs(opt->inputs);  // several: one set of DICOM input
            setActivity(input, "reading");
            const auto [report, text] = app::describeDicom(opt->inputs);
            if (opt->json) printJson(report);
            else fmt::print("{}", text);
            return;
        }
        // Several files (`info *.vdb`): each described in turn.
        opt->request.limits = opt->limits.limits(0);
        nlohmann::json all = nlohmann::json::array();
        std::string text;
        for (const std::string& input : opt->inputs) {
            if (bridge::denseFormatOf(input) == bridge::DenseFormat::Dicom)
                throw Error(input + ": DICOM input is described alone (or with more DICOM input, as one set)");
            setActivity(input, "reading");
            auto [report, lines] = app::describeInput(opt->request, input);
            text += (text.empty() ? "" : "\n") + lines;
            all.push_back(std::move(report));
        }
        if (opt->json) printJson(all.size() == 1 ? all[0] : all);
        else fmt::print("{}", text);
    });
}

} // namespace vdbdag::cli
