// MetaImage headers (ITK's MetaIO): .mhd with ElementDataFile naming a raw
// file beside it, and .mha with "ElementDataFile = LOCAL" (samples right after
// that line). Supported: NDims 3, DimSize, ElementType MET_UCHAR/CHAR/USHORT/
// SHORT/UINT/INT/FLOAT/DOUBLE (MET_(U)LONG, whose width depends on the writer,
// and 64-bit types are refused), ElementSpacing (or
// ElementSize), Offset/Origin/Position, TransformMatrix (alias Rotation/
// Orientation; its rows, as written, are the axis directions),
// BinaryDataByteOrderMSB / ElementByteOrderMSB, HeaderSize (-1 = data at the
// end) and CompressedData (zlib). Lists of data files, multi-channel
// elements and ASCII data are refused with a one-line error.
#pragma once
#include <string>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

DenseVolume readMetaImageHeader(const std::string& path);

} // namespace vdbdag::bridge
