// See EncodeOutputs.h.
#include "app/EncodeOutputs.h"

#include <algorithm>
#include <filesystem>

#include "src/util/Error.h"
#include "src/util/OutputPath.h"

namespace vdbdag::app {

std::string defaultOutputFor(const std::string& input) {
    std::filesystem::path p(input);
    if (!p.has_filename()) p = p.parent_path();  // "dir/"
    std::string name = p.filename().string();
    std::error_code ec;
    if (!std::filesystem::is_directory(p, ec)) {
        std::string lower = name;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (lower.size() > 3 && lower.ends_with(".gz")) name.resize(name.size() - 3);
        if (const size_t dot = name.rfind('.'); dot != std::string::npos && dot > 0) name.resize(dot);
    }
    if (name.empty() || name == "." || name == "..") throw Error(input + ": no name to make the output's from; give -o OUT.ssvdag");
    return (p.parent_path() / (name + ".ssvdag")).string();
}

std::optional<std::vector<std::string>> cacheFrameFiles(const std::string& folder) {
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) return std::nullopt;
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
        if (!e.is_regular_file(ec)) continue;
        const std::string ext = lowerExtension(e.path().string());
        if (ext == ".vdb" || ext == ".nvdb") files.push_back(e.path().string());
        else if (e.path().filename().string()[0] != '.') return std::nullopt;
    }
    if (files.empty()) return std::nullopt;
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<std::string> outputsForEach(const std::vector<std::string>& inputs, const std::string& folder) {
    if (!folder.empty()) {
        std::error_code ec;
        const bool fileName = std::filesystem::path(folder).extension() == ".ssvdag";
        if ((std::filesystem::exists(folder, ec) && !std::filesystem::is_directory(folder, ec)) || (fileName && !std::filesystem::is_directory(folder, ec)))
            throw Error(folder + ": " + std::to_string(inputs.size()) + " inputs are encoded one file each: -o names a folder, not a file");
        std::filesystem::create_directories(folder, ec);
        if (ec) throw Error(folder + ": cannot make the output folder (" + ec.message() + ")");
    }
    std::vector<std::string> outputs;
    for (const std::string& in : inputs) {
        outputs.push_back(folder.empty() ? defaultOutputFor(in) : (std::filesystem::path(folder) / std::filesystem::path(defaultOutputFor(in)).filename()).string());
        if (std::count(outputs.begin(), outputs.end(), outputs.back()) > 1)
            throw Error(in + ": another input is also written to " + outputs.back() + " (inputs of the same name from different folders)");
    }
    return outputs;
}

} // namespace vdbdag::app
