// NIfTI-1 and NIfTI-2 headers (.nii, .nii.gz, .hdr/.img pairs) read with
// libnifti (nifti2_io) into a DenseVolume whose samples DenseSampleStream
// then streams (a .nii.gz is one gzip stream: header, extensions, samples).
//
// Transform, as the NIfTI rules say: the sform when sform_code > 0, else the
// qform when qform_code > 0, else the pixdim scaling alone (method 1).
// Coordinates are RAS (DenseVolume::space "RAS"); scl_slope / scl_inter go
// to DenseVolume::rescaleSlope / rescaleIntercept when scl_slope is neither
// 0 nor 1-with-intercept-0. A 4-D file is one volume per t (`volume` picks
// one, 0-based; DenseImport makes one grid per volume without it); RGB24 is
// a colour, a 5th dimension of 3 a vector; complex and RGBA are refused.
#pragma once
#include <optional>
#include <string>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

// Throws vdbdag::Error naming the file and the header field that is wrong.
// A volume chosen from a 4-D file names its grid NAME_tN (DenseVolume::gridName).
DenseVolume readNiftiHeader(const std::string& path, std::optional<int64_t> volume = std::nullopt);

// The number of volumes (dim[4], at least 1). Throws like readNiftiHeader.
int64_t niftiVolumeCount(const std::string& path);

} // namespace vdbdag::bridge
