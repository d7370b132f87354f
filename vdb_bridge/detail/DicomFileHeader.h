// One DICOM file's header as vdbdag reads it (GDCM, after the element walk
// of DicomElementWalk.h has passed the file): the values every frame of the
// file shares (FileInfo) and one candidate slice per frame (Frame), or the
// reason the file is not an image slice; and the files a DICOMDIR lists.
// DicomSeries.cpp groups the frames into series.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <gdcmDataSet.h>
#include <gdcmFile.h>
#include <gdcmStringFilter.h>

#include <fmt/core.h>

#include "src/util/Error.h"
#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge::detail {

using Vec3 = std::array<double, 3>;

inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 scaled(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// GDCM reports problems on std::cerr unless told not to; vdbdag reports
// them itself, as one-line errors.
void quietGdcm();

// `s` without DICOM's padding (spaces, NULs, line ends) at either end.
std::string trim(std::string s);

// "a\b\c" (DS, IS) as numbers; nullopt when any value is not a number.
std::optional<std::vector<double>> parseNumbers(const std::string& text);

// One element of a data set (top level or an item's), as text.
class Fields {
public:
    explicit Fields(const gdcm::File& file) { filter_.SetFile(file); }
    // Throws vdbdag::Error for an element of a binary VR GDCM's
    // StringFilter has no text for (OD, OL, OV, SV, UV: it asserts,
    // gdcmStringFilter.cxx:471).
    std::string text(const gdcm::DataSet& ds, uint16_t group, uint16_t element) const {
        const gdcm::Tag tag(group, element);
        if (!ds.FindDataElement(tag)) return "";
        const gdcm::DataElement& de = ds.GetDataElement(tag);
        if (de.IsEmpty()) return "";
        if (!stringFilterReads(de.GetVR()))
            throw Error(fmt::format("element ({:04X},{:04X}) has VR {}, which has no text (GDCM's StringFilter aborts on it)", group, element,
                                    gdcm::VR::GetVRString(de.GetVR())));
        return trim(filter_.ToString(de));
    }
    // Empty when absent; nullopt when present but not numbers.
    std::optional<std::vector<double>> numbers(const gdcm::DataSet& ds, uint16_t group, uint16_t element) const {
        return parseNumbers(text(ds, group, element));
    }

private:
    // The VRs StringFilter::ToStringPairInternal turns into text: none read
    // (implicit: the dictionary's), UN (the dictionary's), the text VRs, and
    // the binary ones it has a case for.
    static bool stringFilterReads(gdcm::VR vr) {
        using V = gdcm::VR;
        if (vr == V::INVALID || vr == V::UN || gdcm::VR::IsASCII(vr)) return true;
        for (const V::VRType known : {V::AT, V::FL, V::FD, V::OF, V::SL, V::SS, V::UL, V::US, V::UT, V::OB, V::OW, V::OB_OW, V::SQ})
            if (vr == known) return true;
        return false;
    }
    gdcm::StringFilter filter_;
};

inline constexpr uint16_t kPixelGroup = 0x7fe0;

// A candidate slice: one file, or one frame of a multi-frame file.
struct Frame {
    std::string file;
    uint32_t frame = 0;
    bool multiFrame = false;
    Vec3 position{0, 0, 0};
    std::array<double, 6> orientation{1, 0, 0, 0, 1, 0};
    double rowSpacing = 1, columnSpacing = 1;  // Pixel Spacing [0], [1]
    bool pixelSpacingGiven = false;
    double thickness = 0;  // 0: not given
    double slope = 1, intercept = 0;
};

// What every frame of one file shares.
struct FileInfo {
    std::string file;
    std::string seriesUid, modality, description;
    int64_t seriesNumber = 0;
    uint32_t rows = 0, columns = 0;
    unsigned bitsAllocated = 0, bitsStored = 0, pixelRepresentation = 0, samplesPerPixel = 1;
    std::string photometric;
    std::string damaged;  // why its pixel data cannot be read (a truncated file), or ""
    std::vector<HeaderField> tags;  // DicomTags.h, from the top-level data set
};

// Reads one file's header into `info` and `frames` (one per frame); returns
// the reason to skip it, or "" when it is an image.
std::string readFile(const std::string& path, FileInfo& info, std::vector<Frame>& frames);

// The files a DICOMDIR lists (Referenced File ID, relative to its folder);
// listed files that are missing or lead out of its folder go to `skipped`.
std::vector<std::string> dicomdirFiles(const std::string& path, std::vector<std::string>& skipped);

} // namespace vdbdag::bridge::detail
