// Entry point of the `vdbdag` command: OpenVDB volumes <-> SSVDAG files.
#include "cli/Cli.h"

int main(int argc, char** argv) { return vdbdag::cli::runVdbdag(argc, argv, vdbdag::pipeline::soloTeam()); }
