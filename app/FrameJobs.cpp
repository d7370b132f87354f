#include "app/FrameJobs.h"

#include <filesystem>

#include <fmt/core.h>

#include "src/util/Error.h"
#include "src/util/FramePattern.h"

namespace vdbdag::app {

std::vector<FrameJob> frameJobs(const FrameRequest& r, const std::optional<format::FrameList>& list) {
    const bool pattern = isFramePattern(r.output) && !std::filesystem::exists(r.output);
    if (!list || !list->sequence) {
        if (!r.selection.empty()) throw Error(r.input + ": " + r.option + " applies to sequence files; this file holds one volume");
        if (pattern) throw Error(r.output + ": " + r.input + " holds one volume, not a sequence: -o names one " + r.noun);
        return {FrameJob{std::nullopt, 0, r.output}};
    }
    const std::optional<FrameSelection> selection = r.selection.empty() ? std::nullopt : std::optional(parseFrameSelection(r.selection));
    std::vector<FrameJob> jobs;
    for (uint32_t i = 0; i < list->frames.size(); ++i) {
        const int64_t number = list->frames[i].number;
        if (!selection || selection->contains(number)) jobs.push_back({i, number, pattern ? framePath(r.output, number) : r.output});
    }
    const std::string range = fmt::format("{} frames, {} to {}", list->frames.size(), list->frames.front().number, list->frames.back().number);
    if (jobs.empty()) throw Error(r.input + ": " + r.option + " " + r.selection + " selects none of its " + range);
    if (!pattern && jobs.size() > 1) throw Error(r.input + ": holds " + range + "; " + r.several);
    return jobs;
}

} // namespace vdbdag::app
