// Registration of the `vdbdag` subcommands. Each subcommand lives in its own
// file and is a thin layer over the libraries: parse options, call, print.
#pragma once
#include <CLI/CLI.hpp>

namespace vdbdag::cli {

// Each adds its subcommand to `app`; the callback sets `exitCode`.
void addEncodeCommand(CLI::App& app, int& exitCode);
void addDecodeCommand(CLI::App& app, int& exitCode);
void addInfoCommand(CLI::App& app, int& exitCode);
void addVerifyCommand(CLI::App& app, int& exitCode);
void addImportCommand(CLI::App& app, int& exitCode);

} // namespace vdbdag::cli
