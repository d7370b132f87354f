// How a dense input is read, as the commands' options give it (encode,
// import, Python's vdbdag.encode): the raw layout (dims, type, endian,
// spacing, origin), the DICOM series and further DICOM inputs, the
// background thresholds, a 4-D file's volume. Plain values: the command
// line (cli/DenseInputOptions.h) and other programs fill it; `resolve`
// checks it against one input and gives the bridge's import options.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vdb_bridge/DenseImport.h"

namespace vdbdag::app {

struct DenseInputs {
    std::vector<int64_t> dims;           // raw input: samples along x y z (3 or none)
    std::string type, endian;            // raw input: u8|i8|u16|i16|u32|i32|f32|f64; little|big
    std::vector<double> spacing, origin; // raw input: 3 each or none
    std::string series;                  // DICOM input: a series' number or UID
    std::optional<double> below, above, backgroundValue;  // background thresholds, and the value removed samples become
    std::optional<int64_t> volume;       // 4-D NIfTI or NRRD: which volume
    bool allowExternalData = false, dropPatientTags = false;
    bool noTiles = false;  // --no-tiles: every voxel in its brick (DenseImportOptions::solidBlocks)
    std::vector<std::string> moreInputs; // DICOM: the inputs after the first, read as one set

    // Any option that applies to dense inputs only is set.
    bool anyGiven() const;
    // The positional inputs: the first is the input; more than one are
    // allowed for DICOM only (files, folders, DICOMDIRs scanned as one set),
    // kept in moreInputs. Throws vdbdag::Error naming an input that is not
    // DICOM.
    std::string takeInputs(const std::vector<std::string>& inputs);
    // The bridge's options for `path`. Throws vdbdag::Error naming `path`
    // for an option that does not apply to it or an inconsistent value.
    bridge::DenseImportOptions resolve(const std::string& path) const;
    // Throws vdbdag::Error naming `path` when it is no dense input (a .vdb,
    // a .nvdb) and a dense-only option is set.
    void checkApplies(const std::string& path) const;
};

// The files a command reads for `input`: the input itself and, for a dense
// header (.nhdr, .mhd), the data file it names, for DICOM every slice file of
// the series (an output must be none of them).
std::vector<std::string> denseInputFiles(const std::string& input, const DenseInputs& options);

} // namespace vdbdag::app
