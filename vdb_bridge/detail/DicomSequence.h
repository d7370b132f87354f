// A DICOM sequence kept as bytes, parsed only where GDCM's parse cannot
// allocate what the file does not hold.
//
// GDCM keeps a sequence's value as bytes when it cannot tell it is one as it
// reads the file: an explicit-VR file's sequence written as UN (or OB/OW),
// an implicit-VR file's sequence of defined length. DataElement::GetValueAsSQ
// then parses those bytes, trying up to three encodings in turn (implicit
// VR; for UN also explicit VR byte-swapped, then explicit VR as is; for an
// implicit file's value whose first tag reads (FEFF,00E0), explicit VR
// byte-swapped), and each attempt allocates every element's declared length
// before it reads the element: a 1,600-byte file whose Icon Image Sequence
// (0088,0200) is stored as UN made `info` allocate 4.2 GB (found by
// fuzz_scan_headers; tests/fuzz/regressions/scan_headers/
// dicom_un_icon_sequence_oom). GDCM's image reader parses the icon the same
// way (PixmapReader::DoIconImage).
//
// sequenceProblem walks GDCM's first attempt, implicit VR little endian
// (what DICOM CP-246 asks of a sequence stored as UN), over the bytes and
// bounded by them. It names a declared value length past the bytes larger
// than kMaxUnheldBytes. Where that attempt does not read the bytes to their
// end, GDCM goes on (UN; or an implicit file's sequence whose first tag
// reads (FEFF,00E0)) to byte-swapped and explicit readings with fallbacks
// of their own (another byte order for an item that looks swapped, implicit
// VR after a VR it does not know), which no walk here promises to follow: a
// second finding (dicom_un_icon_sequence_swapped_oom) allocated 850 MB in
// the byte-swapped reading of a little-endian item. Such a sequence is
// refused; otherwise GDCM gives up on the bytes (no sequence), as it is let.
// A smaller overrun is allowed: GDCM allocates it, fails and gives up.
#pragma once
#include <gdcmDataElement.h>
#include <gdcmSequenceOfItems.h>

#include <cstdint>
#include <string>

namespace vdbdag::bridge::detail {

// The largest allocation past the bytes held that a sequence's parse may
// make: 64 MiB.
inline constexpr uint64_t kMaxUnheldBytes = uint64_t(64) << 20;

// Why GDCM must not parse `de`'s value as a sequence ("" when it may, or
// when the value is a sequence already or not one GDCM would parse).
std::string sequenceProblem(const gdcm::DataElement& de);

// GetValueAsSQ once sequenceProblem has nothing to say; else null, with
// `problem` set.
gdcm::SmartPointer<gdcm::SequenceOfItems> valueAsSequence(const gdcm::DataElement& de, std::string& problem);

} // namespace vdbdag::bridge::detail
