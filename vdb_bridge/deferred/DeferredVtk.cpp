// The VTK writers in the light `vdbdag` (src/util/FullCommand.h): each runs
// the command again in vdbdag-full, which has them. Linked instead of
// VtkExport.cpp, VtkDiff.cpp and VtkStructure.cpp.
#include "src/util/FullCommand.h"
#include "vdb_bridge/VtkDiff.h"
#include "vdb_bridge/VtkExport.h"
#include "vdb_bridge/VtkStructure.h"

namespace vdbdag::bridge {

VtkExportReport exportVtk(const std::string&, const std::string&, const VtkExportOptions&) { runFullCommand("VTK output"); }

DiffReport diffVolumes(const std::string&, const std::string&, const std::string&, const DiffOptions&) { runFullCommand("diff"); }

StructureExportReport exportStructure(const std::string&, const std::string&, const StructureExportOptions&) { runFullCommand("VTK output"); }

} // namespace vdbdag::bridge
