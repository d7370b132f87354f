// What vdbdag checks in a DICOM file before GDCM parses it. Debian's GDCM
// is built with its assertions on, and it allocates an element's declared
// length before reading it, so a forged file must never reach it: the walk
// below reads the element headers only (tag, VR, length; into sequences and
// items of undefined length, keeping their nesting) and refuses a length past
// the end of the file, a delimiter outside any sequence, an item tag DICOM
// does not define, a file meta group cut short, with a VR DICOM does not
// define or with a sequence, an element without a VR under an explicit transfer
// syntax (the first too, when the file meta group declares it), an element
// GDCM's image reader reads through gdcm::Attribute<> with an explicit VR
// other than its own (it asserts on one; DicomElementWalk.cpp's kReaderVrs), an item
// whose elements' lengths sum to an odd number where GDCM sums them (in a
// sequence of defined length; it asserts on one), a file
// that ends inside an element, a sequence or an item, a file without
// preamble whose first group is neither 0002 nor 0008, and a DICM prefix
// without the file meta group after it (GDCM guesses how to read those). It also finds the top-level Pixel Data element, so native pixel
// data are read by vdbdag itself (DicomSeries.cpp) and only compressed ones
// are decoded by GDCM's image reader.
#pragma once
#include <cstdint>
#include <string>

namespace vdbdag::bridge::detail {

// The top-level Pixel Data element (7FE0,0010), as the walk found it.
struct DicomPixelData {
    bool found = false;
    bool encapsulated = false;  // undefined length: compressed fragments
    uint64_t offset = 0;        // of its value in the file
    uint64_t length = 0;        // its declared length (not encapsulated)
    bool bigEndian = false;     // the data set's byte order
    std::string transferSyntax; // from the file meta group ("" without one)
};

// "" when the file walks (or is no DICOM at all, which GDCM then reports);
// else the problem, "not a DICOM file (...)" when it starts like no DICOM.
// `beforePixels`: stop at the Pixel Data element. `pixelLength`: set to the
// Pixel Data element's declared length when it is that element that runs
// past the end. `pixels`: the top-level Pixel Data element, when the walk
// reaches it.
std::string elementLengthProblem(const std::string& path, bool beforePixels = false, uint64_t* pixelLength = nullptr,
                                 DicomPixelData* pixels = nullptr);

// GDCM reads a file cut short inside native pixel data without complaint:
// "" when the file holds the `length` bytes its Pixel Data element declares
// (or the element cannot be found), else why not.
std::string checkNativeLength(const std::string& path, uint32_t length, bool bigEndian);

} // namespace vdbdag::bridge::detail
