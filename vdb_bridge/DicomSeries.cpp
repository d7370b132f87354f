// See DicomSeries.h.
#include "vdb_bridge/DicomSeries.h"

#include "src/util/Error.h"

namespace vdbdag::bridge {

DicomScan scanDicom(const std::string& path) { throw Error(path + ": DICOM input is not available yet"); }

DenseVolume describeDicomSeries(const std::string& path, const std::string&) { throw Error(path + ": DICOM input is not available yet"); }

std::unique_ptr<SliceReader> openDicomSlices(const DenseVolume& volume) {
    throw Error(volume.headerPath + ": DICOM input is not available yet");
}

} // namespace vdbdag::bridge
