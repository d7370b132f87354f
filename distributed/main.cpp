// Entry point of `vdbdag-mpi`: the vdbdag command under `mpirun`. Every
// process runs the same command line; `encode` then shares its cubes among
// them (pipeline/CubeTeam.h) and process 0 alone writes the output and
// prints the summary. The file is byte-identical to a single process's.
// Other commands run on process 0 only. A process that fails aborts the
// whole run (MPI_Abort), so none waits forever in a collective.
#include <mpi.h>

#include "cli/Cli.h"
#include "distributed/MpiTeam.h"

int main(int argc, char** argv) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    int code = 0;
    {
        vdbdag::distributed::MpiTeam team;
        code = vdbdag::cli::runVdbdag(argc, argv, team);
        if (code != 0 && team.size() > 1) MPI_Abort(MPI_COMM_WORLD, code);
    }
    MPI_Finalize();
    return code;
}
