// The stiff and extreme cases of issue 7 part 2 (`vdbdag selftest` and
// tests/unit/test_selftest.cpp): a registry of cases, each with a group
// (values, geometry, colours, normals, rays), a name, the bound it checks
// (bit-exact, error <= tolerance, size <= bound, no NaN produced) and, once
// run, the measured figure and whether the bound held. A bound that cannot
// be met is reported as failed, never loosened: the bound text is fixed when
// the case is registered, before anything is measured. Core only (no
// OpenVDB): every case builds its own grids, rays or vectors and compares
// against an independent reference (a brute-force voxel walk, the exact
// rational ray reference, closed-form bounds, published values).
#pragma once
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace vdbdag::selftest {

// What running a case measured: `value` is the headline figure, short
// enough for a table column ("max rel 0.001", "0 mismatches"); `measured`
// the full figures (and, on failure, the first violation). `passed` only
// when every check held.
struct Measurement {
    std::string value;
    std::string measured;
    bool passed = false;
};

struct SelftestCase {
    std::string group;  // values, geometry, colours, normals, rays
    std::string name;
    std::string limit;  // the bound in a few words, for the table ("rel err <= 0.001")
    std::string bound;  // the bound in full: what must hold, fixed before the case runs
    std::function<Measurement()> run;

    std::string id() const { return group + "/" + name; }
};

struct CaseResult {
    std::string group, name, limit, bound, value, measured;
    bool passed = false;
    double seconds = 0;

    std::string id() const { return group + "/" + name; }
};

// Every case, in report order (groups values, geometry, colours, normals,
// rays). Building the list is cheap: nothing runs until a case is run.
const std::vector<SelftestCase>& selftestCases();

// Runs one case; an exception thrown by the case is a failure whose
// measured text is the exception's message.
CaseResult runCase(const SelftestCase& c);

// Runs every case whose id ("group/name") contains `filter` (all when it is
// empty), in registry order; `onCase` is called after each.
std::vector<CaseResult> runSelftest(std::string_view filter = {},
                                    const std::function<void(const CaseResult&)>& onCase = {});

// Number of cases matching `filter`.
size_t countSelftestCases(std::string_view filter = {});

// Collects the checks of one case: the first failed check's message is kept
// (for the measured text), later ones only counted.
class Checks {
public:
    // Records a failed check when `ok` is false; returns ok.
    bool require(bool ok, const std::string& whatFailed);
    bool passed() const { return failures_ == 0; }
    // `value` (the headline figure) and `figure` (the full figures) followed,
    // on failure, by the first violation and the count.
    Measurement result(const std::string& value, const std::string& figure) const;

private:
    std::string first_;
    size_t failures_ = 0;
};

} // namespace vdbdag::selftest
