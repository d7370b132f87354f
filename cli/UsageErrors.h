// How the command line answers a mistake in itself rather than in its
// input: one line "vdbdag[ COMMAND]: what is wrong[; did you mean X?] (see
// vdbdag[ COMMAND] --help)" and exit status 2, the usage status of diff,
// cmp, zstd and git. Help and --version print and exit 0. `vdbdag help
// [COMMAND]` is the same as `vdbdag [COMMAND] --help`.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace vdbdag::cli {

inline constexpr int kUsageExitCode = 2;

// The exit status for `e`, after printing help, the version or the line.
int answerParseError(CLI::App& app, const CLI::ParseError& e, int argc, char** argv);

// `vdbdag help [COMMAND]`: the exit status when argv asks for it.
std::optional<int> answerHelpCommand(CLI::App& app, int argc, char** argv);

// The name in `names` closest to `word` when one is close enough to be
// what was meant (a typo, or the start of only one name); else empty.
std::string closestName(const std::string& word, const std::vector<std::string>& names);

} // namespace vdbdag::cli
