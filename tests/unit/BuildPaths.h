// Where the build put the programs the tests run, and where the sources and
// ../shared/data are. The paths live in one generated source file
// (build/test_build_paths.cpp, written by CMakeLists.txt) and not on every
// test's command line, so that a test's object does not depend on where the
// checkout is: a compiler cache (ccache, scripts/setup.sh) serves a fresh
// clone of the same sources.
#pragma once

namespace vdbdag::testing::build {
extern const char* const sourceDir;   // the checkout
extern const char* const sharedData;  // ../shared/data beside it (may be absent)
extern const char* const binary;      // vdbdag
extern const char* const samplesTool;
extern const char* const sequenceTool;
extern const char* const vdbProbe;
extern const char* const phantomTool;
extern const char* const mpiBinary;  // "" without MPI
extern const char* const mpirun;     // "" without MPI
}  // namespace vdbdag::testing::build

#define VDBDAG_SOURCE_DIR ::vdbdag::testing::build::sourceDir
#define VDBDAG_SHARED_DATA ::vdbdag::testing::build::sharedData
#define VDBDAG_BINARY ::vdbdag::testing::build::binary
#define VDBDAG_SAMPLES_TOOL ::vdbdag::testing::build::samplesTool
#define VDBDAG_SEQUENCE_TOOL ::vdbdag::testing::build::sequenceTool
#define VDBDAG_VDB_PROBE ::vdbdag::testing::build::vdbProbe
#define VDBDAG_PHANTOM_TOOL ::vdbdag::testing::build::phantomTool
#if VDBDAG_TEST_HAS_MPI
#define VDBDAG_MPI_BINARY ::vdbdag::testing::build::mpiBinary
#define VDBDAG_MPIRUN ::vdbdag::testing::build::mpirun
#endif
