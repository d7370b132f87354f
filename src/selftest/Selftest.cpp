// See Selftest.h: the registry and the runner.
#include "src/selftest/Selftest.h"

#include <chrono>
#include <exception>

#include <fmt/core.h>

#include "src/selftest/CaseGroups.h"

namespace vdbdag::selftest {

const std::vector<SelftestCase>& selftestCases() {
    static const std::vector<SelftestCase> cases = [] {
        std::vector<SelftestCase> all;
        addValueCases(all);
        addGeometryCases(all);
        addColourCases(all);
        addNormalCases(all);
        addRayCases(all);
        return all;
    }();
    return cases;
}

CaseResult runCase(const SelftestCase& c) {
    CaseResult result{c.group, c.name, c.limit, c.bound, {}, {}, false, 0};
    const auto start = std::chrono::steady_clock::now();
    try {
        Measurement m = c.run ? c.run() : Measurement{"no case function", "no case function", false};
        result.value = std::move(m.value);
        result.measured = std::move(m.measured);
        result.passed = m.passed;
    } catch (const std::exception& e) {
        result.value = "threw";
        result.measured = fmt::format("threw: {}", e.what());
        result.passed = false;
    } catch (...) {
        result.value = "threw";
        result.measured = "threw a non-standard exception";
        result.passed = false;
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

std::vector<CaseResult> runSelftest(std::string_view filter, const std::function<void(const CaseResult&)>& onCase) {
    std::vector<CaseResult> results;
    for (const SelftestCase& c : selftestCases()) {
        if (!filter.empty() && c.id().find(filter) == std::string::npos) continue;
        results.push_back(runCase(c));
        if (onCase) onCase(results.back());
    }
    return results;
}

size_t countSelftestCases(std::string_view filter) {
    size_t n = 0;
    for (const SelftestCase& c : selftestCases()) n += filter.empty() || c.id().find(filter) != std::string::npos;
    return n;
}

bool Checks::require(bool ok, const std::string& whatFailed) {
    if (!ok) {
        if (failures_ == 0) first_ = whatFailed;
        ++failures_;
    }
    return ok;
}

Measurement Checks::result(const std::string& value, const std::string& figure) const {
    if (failures_ == 0) return {value, figure, true};
    return {value, fmt::format("{}; VIOLATED: {}{}", figure, first_, failures_ > 1 ? fmt::format(" (+{} more)", failures_ - 1) : ""), false};
}

} // namespace vdbdag::selftest
