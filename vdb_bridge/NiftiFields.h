// Every field of a NIfTI-1 or NIfTI-2 header as named metadata, and back.
//
// On import each field goes to the grid's metadata as "nifti_" + its name
// in the standard (nifti1.h / nifti2.h): integers as int64, floating-point
// fields as double (exact for both versions), strings as strings, arrays
// (dim, pixdim, srow_x/y/z) as one string of numbers, %.17g each. Header
// extensions go as "nifti_extension_N_code" (int64) and "nifti_extension_N"
// (base64 of the payload). "nifti_version" is 1 or 2. The fields that only
// describe the file's layout (sizeof_hdr, datatype, bitpix, vox_offset,
// magic) are not kept: a writer derives them. docs/SCAN_METADATA.md lists
// the keys.
//
// On export to .nii / .nii.gz the fields come back over the header the
// writer computed from the grid:
// - the orientation (qform and sform codes and matrices, quatern and qoffset,
//   pixdim[0..3]) only when the grid's transform is still the one those
//   fields give, by the rule the reader used (sform, else qform, else
//   pixdim); otherwise the grid's transform is written and a note says so;
// - dim[0] and dim[4..7] with pixdim[4..7] when the sample count matches;
// - scl_slope / scl_inter when they give the same values as the writer's;
// - everything else (intent, descrip, aux_file, units, slice timing, cal,
//   toffset, dim_info, the ANALYZE leftovers of NIfTI-1) as it came.
#pragma once
#include <array>
#include <map>
#include <string>
#include <vector>

#include "vdb_bridge/DenseVolume.h"

struct nifti_1_header;
struct nifti_2_header;

namespace vdbdag::bridge {

using HeaderFieldMap = std::map<std::string, HeaderField::Value>;

// The fields of the header at `path` (read raw, in native byte order) and
// its extensions. Throws vdbdag::Error naming the file.
std::vector<HeaderField> niftiFieldsOf(const std::string& path);

// The grid transform those fields give, as the reader builds it (RAS
// turned into LPS when a qform or sform is used); false when `fields`
// holds no NIfTI header.
struct NiftiGridTransform {
    std::array<std::array<double, 3>, 3> axes{};  // index axis a's world vector
    std::array<double, 3> origin{};
    bool lps = false;  // the header names an orientation (qform or sform)
};
bool niftiGridTransformOf(const HeaderFieldMap& fields, NiftiGridTransform& out);

// Puts the recorded fields back into a header the writer filled from the
// grid. `geometry`: the grid's transform equals niftiGridTransformOf's.
// `rescale`: the slope and intercept the writer set (0, 0: none). Returns
// the notes a user should read (what could not go back, and why).
struct NiftiRestore {
    bool geometry = false;
    double slope = 0, intercept = 0;
};
std::vector<std::string> restoreNiftiFields(const HeaderFieldMap& fields, const NiftiRestore& how, nifti_1_header& h);
std::vector<std::string> restoreNiftiFields(const HeaderFieldMap& fields, const NiftiRestore& how, nifti_2_header& h);
// The recorded extensions, each as (code, payload), in file order.
std::vector<std::pair<int, std::string>> niftiExtensionsOf(const HeaderFieldMap& fields);

} // namespace vdbdag::bridge
