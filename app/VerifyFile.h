// `vdbdag verify` of one input as a library call: encode a .vdb (or a
// NanoVDB .nvdb, as its grids read through NanoVDB; or a scan, as its grids
// are imported), write the .ssvdag, read it back, decode, and compare with
// the original file using OpenVDB alone: headers, topology, every active
// value and every stored inactive value, bit for bit. Or compare a given
// .ssvdag (what `encode` wrote).
//
// A scan (NIfTI, NRRD, MetaImage, raw, DICOM) is imported as `encode`
// imports it with the same options (vdb_bridge/DenseImport.h: its samples
// after any rescale, thresholds and tiles), into a temporary .vdb in the
// scratch folder, which is then verified as a .vdb is: every sample as the
// import reads it is compared through OpenVDB's accessors (a fault of the
// import itself would be on both sides; the scan readers have their own
// tests against nibabel and pydicom).
//
// A .vdb with grid offsets goes the way `encode` takes it (region by
// region, within the memory limit) into a temporary file in the scratch
// folder, and is compared cube by cube (vdb_bridge/VdbStreamCompare.h):
// neither side is ever a whole grid. An OpenVDB stream is read, encoded
// and compared whole, in memory (vdb_bridge/VdbCompare.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "src/format/ReadLimits.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/VdbCompare.h"

namespace vdbdag::app {

struct VerifyRequest {
    std::string input;                // a .vdb or .nvdb file, or a scan
    std::string encoded;              // compare this .ssvdag with the input instead of encoding one (empty: encode)
    std::optional<uint32_t> frame;    // `encoded` is a sequence: the frame (an index) compared with the input
    std::string scratch;              // the encoded file and the scratch files (empty: the system's temporary folder)
    bool noSymmetry = false, topologyOnly = false;  // the encoding verified
    uint64_t memoryLimit = 0;         // the encode's working memory (0: half the physical memory)
    format::ReadLimits limits;        // what `encoded` may expand to (a file from elsewhere)
    bridge::DenseImportOptions dense; // how a scan is read (as `encode` would read it)
};

struct VerifyResult {
    bridge::CompareResult result;  // identical, or what differs
    uint64_t bytes = 0;            // the .ssvdag file's size
    size_t grids = 0;
    nlohmann::json report;         // as `verify --json` prints it
};

// Throws vdbdag::Error naming the file on a refusal (an unreadable input,
// a forged --encoded file, a full scratch disk); temporary files are removed.
// Progress on a terminal.
VerifyResult verifyFile(const VerifyRequest& request);

} // namespace vdbdag::app
