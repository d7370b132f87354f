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
// sequenceProblem walks each attempt GDCM would make, in its order, over the
// bytes and bounded by them, up to the first that reads to the end; it names
// the first declared length past the bytes left that is larger than
// kMaxUnheldBytes (GDCM would allocate it, then fail and try the next
// encoding). A smaller one is allowed: GDCM's first, implicit attempt at a
// valid explicit-VR sequence stored as UN reads each element's VR and short
// length as one 4-byte length (US and 2 bytes: 152,405), allocates that and
// fails; only a value of 4 KB or more would make it exceed the bound.
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
