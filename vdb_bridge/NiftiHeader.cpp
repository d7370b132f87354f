// See NiftiHeader.h.
#include "vdb_bridge/NiftiHeader.h"

#include "src/util/Error.h"

namespace vdbdag::bridge {

DenseVolume readNiftiHeader(const std::string& path, std::optional<int64_t>) { throw Error(path + ": NIfTI input is not available yet"); }

} // namespace vdbdag::bridge
