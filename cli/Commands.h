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
void addRenderCommand(CLI::App& app, int& exitCode);
void addBenchCommand(CLI::App& app, int& exitCode);
void addDevicesCommand(CLI::App& app, int& exitCode);
void addExportCommand(CLI::App& app, int& exitCode);
void addDiffCommand(CLI::App& app, int& exitCode);
void addSelftestCommand(CLI::App& app, int& exitCode);
void addImportCommand(CLI::App& app, int& exitCode);

} // namespace vdbdag::cli
