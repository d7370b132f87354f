// The self-test entry points in the products (vdbdag, vdbdag-full,
// vdbdag-mpi), which link none of src/selftest/: each runs the command again
// in vdbdag-selftest (src/util/FullCommand.h), built from vdbdag_selftest.
#include "src/selftest/Selftest.h"
#include "src/util/FullCommand.h"

namespace vdbdag::selftest {

const std::vector<SelftestCase>& selftestCases() { runHelperCommand("vdbdag-selftest", "selftest"); }

std::vector<CaseResult> runSelftest(std::string_view, const std::function<void(const CaseResult&)>&) { runHelperCommand("vdbdag-selftest", "selftest"); }

size_t countSelftestCases(std::string_view) { runHelperCommand("vdbdag-selftest", "selftest"); }

} // namespace vdbdag::selftest
