// The whole `vdbdag` command line (parsing, subcommands, one-line errors)
// run by a process of `team`: soloTeam() for the plain binary, the MPI
// processes for vdbdag-mpi (distributed/main.cpp). Returns the exit code.
#pragma once
#include "src/pipeline/CubeTeam.h"

namespace vdbdag::cli {

int runVdbdag(int argc, char** argv, pipeline::CubeTeam& team);

} // namespace vdbdag::cli
