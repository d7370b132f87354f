// GDCM's DICOM reader in the light `vdbdag` (src/util/FullCommand.h): a
// DICOM input runs the command again in vdbdag-full, which reads it, before
// anything is written. Linked instead of DicomSeries.cpp.
#include "src/util/FullCommand.h"
#include "vdb_bridge/DicomSeries.h"

namespace vdbdag::bridge {

DicomScan scanDicom(const std::vector<std::string>&) { runFullCommand("DICOM input"); }

DenseVolume describeDicomSeries(const std::vector<std::string>&, const std::string&) { runFullCommand("DICOM input"); }

std::string dicomInputName(const std::vector<std::string>&) { runFullCommand("DICOM input"); }

std::unique_ptr<SliceReader> openDicomSlices(const DenseVolume&) { runFullCommand("DICOM input"); }

} // namespace vdbdag::bridge
