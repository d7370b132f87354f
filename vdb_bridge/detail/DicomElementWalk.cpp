// The element walk that guards GDCM (see DicomElementWalk.h).
#include "vdb_bridge/detail/DicomElementWalk.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <vector>

#include <fmt/core.h>

namespace vdbdag::bridge::detail {
namespace fs = std::filesystem;
constexpr uint16_t kPixelGroup = 0x7fe0;

// GDCM reads a file cut short inside native (uncompressed) pixel data
// without complaint. The Pixel Data element's header is found in the file
// (its tag followed by its length, explicit or implicit VR, the first such
// match) and the file must hold all of its value. Returns "" when it does or
// when the element cannot be found (deflated data sets).
std::string checkNativeLength(const std::string& path, uint32_t length, bool bigEndian) {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) return "";
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    const uint8_t tag[4] = {uint8_t(bigEndian ? 0x7f : 0xe0), uint8_t(bigEndian ? 0xe0 : 0x7f), uint8_t(bigEndian ? 0x00 : 0x10),
                            uint8_t(bigEndian ? 0x10 : 0x00)};
    const auto u32 = [&](const uint8_t* p) {
        return bigEndian ? uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]
                         : uint32_t(p[3]) << 24 | uint32_t(p[2]) << 16 | uint32_t(p[1]) << 8 | p[0];
    };
    constexpr size_t kChunk = size_t(1) << 16, kKeep = 12;
    std::vector<uint8_t> buf;
    uint64_t bufStart = 0;  // file offset of buf[0]
    std::string result;
    std::vector<uint8_t> chunk(kChunk);
    for (;;) {
        const size_t got = std::fread(chunk.data(), 1, kChunk, file);
        buf.insert(buf.end(), chunk.begin(), chunk.begin() + ptrdiff_t(got));
        bool found = false;
        for (size_t i = 0; i + kKeep <= buf.size() && !found; ++i) {
            if (std::memcmp(buf.data() + i, tag, 4) != 0) continue;
            const uint8_t* p = buf.data() + i + 4;
            uint64_t header = 0;
            if ((p[0] == 'O' && (p[1] == 'W' || p[1] == 'B')) && p[2] == 0 && p[3] == 0 && u32(p + 4) == length) header = 12;
            else if (u32(p) == length) header = 8;
            if (!header) continue;
            found = true;
            const uint64_t end = bufStart + i + header + length;
            if (end > size)
                result = fmt::format("is truncated: its pixel data are {} bytes from byte {} on, but the file holds only {} of them", length, bufStart + i + header,
                                     size - (bufStart + i + header));
        }
        if (found || got < kChunk) break;
        if (buf.size() > kKeep) {  // keep the tail: a header may straddle chunks
            bufStart += buf.size() - kKeep;
            buf.erase(buf.begin(), buf.end() - ptrdiff_t(kKeep));
        }
    }
    std::fclose(file);
    return result;
}

namespace {

// The elements GDCM's image reader (ImageReader::ReadImage,
// PixmapReader::ReadImageInternal and ReadACRNEMAImage, the ImageHelper
// functions they call: spacing, origin, direction cosines, rescale,
// dimensions; the icon image, overlays and curves) reads through
// gdcm::Attribute<>, or checks against its dictionary VR by hand, as GDCM
// 3.0's dictionary types them. Attribute<>::SetFromDataElement asserts
// (aborts) that an element's VR is Compatible() with the attribute's:
// the same VR, or UN, or none (implicit VR); GetSpacingValue asserts the
// same of the spacing tag its media storage names, and that the Z spacing
// tag's VR is its dictionary VR. So under an explicit VR any other VR for
// one of these, at any depth (GDCM reads several from functional group,
// ultrasound region, icon image and detector items), is refused before
// GDCM reads the file: an Image Orientation (Patient) of VR AS in an RLE
// file aborted in GetDirectionCosinesFromDataSet (found by
// fuzz_scan_headers). Not here: what the reader takes as bytes
// (Photometric Interpretation, the palette descriptors through Element<>,
// which checks no VR) or not at all (Slice Thickness, Real World Value
// Intercept/Slope: code GDCM 3.0.21 compiles out). `group` matches under
// `groupMask`: the even overlay (60xx) and curve (50xx) groups GDCM reads
// as one.
struct ReaderVr {
    uint16_t group, groupMask, element;
    const char* vrs;   // the VRs GDCM takes (UN always passes too)
    const char* name;
};
constexpr ReaderVr kReaderVrs[] = {
    {0x0018, 0xFFFF, 0x0088, "DS", "Spacing Between Slices"},
    {0x0018, 0xFFFF, 0x1063, "DS", "Frame Time"},
    {0x0018, 0xFFFF, 0x1164, "DS", "Imager Pixel Spacing"},
    {0x0018, 0xFFFF, 0x2010, "DS", "Nominal Scanned Pixel Spacing"},
    {0x0018, 0xFFFF, 0x602C, "FD", "Physical Delta X"},
    {0x0018, 0xFFFF, 0x602E, "FD", "Physical Delta Y"},
    {0x0020, 0xFFFF, 0x0030, "DS", "Image Position (retired)"},
    {0x0020, 0xFFFF, 0x0032, "DS", "Image Position (Patient)"},
    {0x0020, 0xFFFF, 0x0035, "DS", "Image Orientation (retired)"},
    {0x0020, 0xFFFF, 0x0037, "DS", "Image Orientation (Patient)"},
    {0x0028, 0xFFFF, 0x0002, "US", "Samples per Pixel"},
    {0x0028, 0xFFFF, 0x0005, "US SS", "Image Dimensions"},  // ReadACRNEMAImage reads SS apart
    {0x0028, 0xFFFF, 0x0006, "US", "Planar Configuration"},
    {0x0028, 0xFFFF, 0x0008, "IS", "Number of Frames"},
    {0x0028, 0xFFFF, 0x0009, "AT", "Frame Increment Pointer"},
    {0x0028, 0xFFFF, 0x0010, "US", "Rows"},
    {0x0028, 0xFFFF, 0x0011, "US", "Columns"},
    {0x0028, 0xFFFF, 0x0012, "US", "Planes"},
    {0x0028, 0xFFFF, 0x0030, "DS", "Pixel Spacing"},
    {0x0028, 0xFFFF, 0x0034, "IS", "Pixel Aspect Ratio"},
    {0x0028, 0xFFFF, 0x0100, "US", "Bits Allocated"},
    {0x0028, 0xFFFF, 0x0101, "US", "Bits Stored"},
    {0x0028, 0xFFFF, 0x0102, "US", "High Bit"},
    {0x0028, 0xFFFF, 0x0103, "US", "Pixel Representation"},
    {0x0028, 0xFFFF, 0x1052, "DS", "Rescale Intercept"},
    {0x0028, 0xFFFF, 0x1053, "DS", "Rescale Slope"},
    {0x0028, 0xFFFF, 0x2110, "CS", "Lossy Image Compression"},
    {0x3002, 0xFFFF, 0x0011, "DS", "Image Plane Pixel Spacing"},
    {0x3004, 0xFFFF, 0x000C, "DS", "Grid Frame Offset Vector"},
    {0x3004, 0xFFFF, 0x000E, "DS", "Dose Grid Scaling"},
    {0x5000, 0xFF01, 0x0005, "US", "Curve Dimensions"},
    {0x5000, 0xFF01, 0x0010, "US", "Number of Points"},
    {0x5000, 0xFF01, 0x0103, "US", "Data Value Representation"},
    {0x5000, 0xFF01, 0x0110, "US", "Curve Data Descriptor"},
    {0x5000, 0xFF01, 0x0112, "US", "Coordinate Start Value"},
    {0x5000, 0xFF01, 0x0114, "US", "Coordinate Step Value"},
    {0x6000, 0xFF01, 0x0010, "US", "Overlay Rows"},
    {0x6000, 0xFF01, 0x0011, "US", "Overlay Columns"},
    {0x6000, 0xFF01, 0x0015, "IS", "Number of Frames in Overlay"},
    {0x6000, 0xFF01, 0x0050, "SS", "Overlay Origin"},
    {0x6000, 0xFF01, 0x0051, "US", "Image Frame Origin"},
    {0x6000, 0xFF01, 0x0100, "US", "Overlay Bits Allocated"},
    {0x6000, 0xFF01, 0x0102, "US", "Overlay Bit Position"},
    {0x6000, 0xFF01, 0x0200, "US", "Overlay Location"},
};

// "" when GDCM's image reader takes an element of this tag and explicit VR,
// else why not.
std::string readerVrProblem(uint16_t group, uint16_t element, const char* vr, uint64_t pos) {
    for (const ReaderVr& r : kReaderVrs) {
        if ((group & r.groupMask) != r.group || element != r.element) continue;
        if (std::strcmp(vr, "UN") == 0) return "";
        for (const char* v = r.vrs; *v; v += v[2] ? 3 : 2)
            if (v[0] == vr[0] && v[1] == vr[1]) return "";
        return fmt::format("element ({:04X},{:04X}) {} at byte {} has VR {}, which GDCM's image reader aborts on (it takes {} or UN only)", group,
                           element, r.name, pos, vr, r.vrs[2] ? "US, SS" : r.vrs);
    }
    return "";
}

// GDCM allocates each element's declared length before it reads the bytes,
// so a 1 KB file that declares a 3 GB element makes it allocate (and touch)
// 3 GB. This walk reads only the element headers (tag, VR, length; into
// sequences and items of undefined length) and refuses any length that runs
// past the end of the file, before GDCM sees it. "" when the file passes
// (or is not DICOM at all, which GDCM then reports). `beforePixels`: stop at
// the Pixel Data element (a header read; a short pixel data element is a
// truncated slice, which the series check names).
// `pixelLength`: set to the Pixel Data element's declared length when it is
// that element that runs past the end.
std::string walkElementLengths(const std::string& path, bool beforePixels, uint64_t* pixelLength, bool& unknownStart, DicomPixelData* pixels) {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) return "";
    struct Closer {
        std::FILE* f;
        ~Closer() { std::fclose(f); }
    } closer{file};
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    if (ec) return "";
    auto readAt = [&](uint64_t at, void* out, size_t n) {
        return at + n <= size && std::fseek(file, long(at), SEEK_SET) == 0 && std::fread(out, 1, n, file) == n;
    };
    uint64_t pos = 0;
    char magic[4];
    if (readAt(128, magic, 4) && std::memcmp(magic, "DICM", 4) == 0) pos = 132;
    bool explicitVr = true, bigEndian = false, metaGroup = pos == 132, declaredImplicit = false;
    bool datasetStarted = false;  // an element after the file meta group was walked
    unknownStart = false;
    // After the DICM prefix the file meta group (0002) comes first; GDCM
    // guesses its way through a file where it does not (it read 295 bytes
    // whose first element was (FFFF,FFFF) big-endian and allocated 2 GB:
    // found by fuzz_scan_headers).
    if (pos == 132) {
        uint8_t t[4];
        if (readAt(132, t, 4) && (t[0] | t[1] << 8) != 0x0002)
            return fmt::format("no file meta group after the DICM prefix: its first element is ({:04X},{:04X})", uint16_t(t[0] | t[1] << 8),
                               uint16_t(t[2] | t[3] << 8));
    }
    if (pos == 0) {  // no preamble: walk only what starts like a DICOM dataset (else GDCM refuses it as not DICOM)
        uint8_t h[6];
        // GDCM asserts (aborts) on a file shorter than one element header
        // (02 00 00 00, E0 7F 10 00: found by fuzz_scan_headers).
        if (size > 0 && size < 8) return fmt::format("the file ({} bytes) ends inside its first element", size);
        if (!readAt(0, h, 6)) return "";
        uint16_t group = uint16_t(h[0] | h[1] << 8);
        if (group == 0x0200 || group == 0x0800) {  // big-endian: GDCM reads it so (and asserts on a cut-off element)
            bigEndian = true;
            group = uint16_t(h[0] << 8 | h[1]);
        }
        // Neither a file meta group nor a data set's first group: GDCM still
        // parses it, guessing its byte order and VRs, and the walk cannot
        // follow its guesses (it allocated 1.8 GB for a 107-byte file whose
        // bytes read as a 1.8 GB element, 2 GB for 9 KB it read big-endian,
        // and aborted on others: found by fuzz_scan_headers). Such a file is
        // no DICOM vdbdag reads.
        unknownStart = group != 0x0002 && group != 0x0008;
        if (unknownStart)
            return fmt::format("its first element ({:04X},{:04X}) is of neither the file meta group (0002) nor a data set's first group (0008)", group,
                               uint16_t(bigEndian ? h[2] << 8 | h[3] : h[2] | h[3] << 8));
        explicitVr = std::isupper(h[4]) && std::isupper(h[5]);
        declaredImplicit = !explicitVr && !unknownStart;
        metaGroup = group == 0x0002;
    }
    auto u16 = [&](const uint8_t* b) { return bigEndian ? uint16_t(b[0] << 8 | b[1]) : uint16_t(b[0] | b[1] << 8); };
    auto u32 = [&](const uint8_t* b) {
        return bigEndian ? uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3] : uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
    };
    std::string transferSyntax;
    bool declaredSyntax = false;  // the file meta group holds a transfer syntax (0002,0010)
    // Where the walk is: the data set, a sequence (its items), encapsulated
    // pixel data (their fragments) or an item (its elements), each of a
    // defined length (it ends at `end`) or an undefined one (a delimiter
    // ends it). GDCM asserts on an item where an element belongs and on an
    // element where an item belongs, so neither passes.
    enum class Kind { DataSet, Sequence, Fragments, Item };
    // GDCM sums the lengths of an item's elements (Item::GetLength) for
    // each item of a sequence of defined length, and for each item of a
    // sequence of undefined length inside such an item or an item of defined
    // length (DataSet::ReadWithLength sums its elements' lengths), and
    // asserts that the sum is even: `checked` marks those sequences and items, `odd` the
    // parity of an item's element lengths so far, `oddAt` its last element
    // of odd length (a 4x4 RLE file whose icon item held elements of 1, 1
    // and 257 bytes aborted in gdcm::Reader).
    struct OddElement {
        uint16_t group = 0, element = 0;
        uint64_t pos = 0, length = 0;
    };
    struct Frame {
        Kind kind;
        uint64_t end;  // 0: undefined length
        uint64_t start = 0;
        bool checked = false, odd = false;
        OddElement oddAt{};
    };
    std::vector<Frame> frames{{Kind::DataSet, 0}};
    const auto enter = [&](Kind kind, uint64_t at, uint64_t length) -> std::string {
        if (frames.size() >= 64) return fmt::format("sequences nested more than 64 deep at byte {}", at);
        const Frame& parent = frames.back();
        const bool checked = kind == Kind::Item ? parent.checked
                                                : kind == Kind::Sequence && (length != 0xFFFFFFFFu || (parent.kind == Kind::Item && (parent.checked || parent.end)));
        frames.push_back({kind, length == 0xFFFFFFFFu ? 0 : at + length, at, checked, false, {}});
        return "";
    };
    // Leaving a frame: an item GDCM sums is refused when its sum is odd.
    const auto leave = [&]() -> std::string {
        const Frame f = frames.back();
        frames.pop_back();
        if (f.kind == Kind::Item && f.checked && f.odd)
            return fmt::format("the item at byte {} holds elements of odd total length (its element ({:04X},{:04X}) at byte {} is {} bytes long), which GDCM "
                               "asserts on in a sequence of defined length",
                               f.start - 8, f.oddAt.group, f.oddAt.element, f.oddAt.pos, f.oddAt.length);
        return "";
    };
    for (unsigned steps = 0; steps < 10'000'000; ++steps) {
        while (frames.size() > 1 && frames.back().end && pos >= frames.back().end) {
            if (pos > frames.back().end) return fmt::format("an element at byte {} runs past the end of its sequence or item", pos);
            if (const std::string bad = leave(); !bad.empty()) return bad;
        }
        // GDCM asserts on an element cut off after its tag, whatever the
        // file starts with (a 291-byte file whose first group is 0000 and
        // whose last 5 bytes are a tag and a byte: found by fuzz_scan_headers).
        if (pos + 8 > size) {
            if (pos < size) return fmt::format("the file ends inside an element (its last {} bytes, from byte {})", size - pos, pos);
            break;
        }
        const Kind where = frames.back().kind;
        uint8_t h[12];
        if (!readAt(pos, h, 8)) break;
        const bool inMeta = metaGroup && (h[0] | h[1] << 8) == 0x0002;
        if (metaGroup && !inMeta) {  // the meta group ends: the dataset's encoding from its transfer syntax
            metaGroup = false;
            // Implicit VR: DICOM's, and GE's private "implicit VR big endian"
            // (only its pixels are big-endian; GDCM reads it as implicit).
            if (transferSyntax == "1.2.840.10008.1.2" || transferSyntax == "1.2.840.113619.5.2") explicitVr = false, declaredImplicit = true;
            else if (transferSyntax == "1.2.840.10008.1.2.2") bigEndian = true;
            else if (transferSyntax == "1.2.840.10008.1.2.1.99") return "";  // deflated: GDCM inflates and checks
            // A transfer syntax DICOM does not define: GDCM then guesses the
            // encoding element by element and allocated 2.9 GB for a 483-byte
            // file (fuzz_scan_headers); the walk cannot follow its guesses.
            if (!transferSyntax.empty() && transferSyntax != "1.2.840.10008.1.2" && transferSyntax.rfind("1.2.840.10008.1.2.", 0) != 0 &&
                transferSyntax != "1.2.840.113619.5.2")
                return fmt::format("its transfer syntax '{}' is none DICOM defines",
                                   transferSyntax.size() > 64 ? transferSyntax.substr(0, 64) + "..." : transferSyntax);
        }
        const bool le = inMeta || !bigEndian;
        const uint16_t group = le ? uint16_t(h[0] | h[1] << 8) : u16(h), element = le ? uint16_t(h[2] | h[3] << 8) : u16(h + 2);
        uint64_t length, header;
        if (group == 0xFFFE) {  // item and delimiters: always a 4-byte length
            length = le ? uint32_t(h[4]) | uint32_t(h[5]) << 8 | uint32_t(h[6]) << 16 | uint32_t(h[7]) << 24 : u32(h + 4);
            header = 8;
            const bool inSequence = where == Kind::Sequence || where == Kind::Fragments;
            if (element == 0xE000) {
                if (!inSequence) return fmt::format("an item (FFFE,E000) at byte {} where an element belongs", pos);
                if (length != 0xFFFFFFFFu && length > size - pos - header)
                    return fmt::format("item at byte {} claims {} bytes, but only {} follow", pos, length, size - pos - header);
                pos += header;
                // A fragment is bytes; an item holds elements.
                if (where == Kind::Fragments) pos += length == 0xFFFFFFFFu ? 0 : length;
                else if (const std::string bad = enter(Kind::Item, pos, length); !bad.empty()) return bad;
                continue;
            }
            const bool endsItem = element == 0xE00D && where == Kind::Item, endsSequence = element == 0xE0DD && inSequence;
            if (element != 0xE00D && element != 0xE0DD) return fmt::format("unknown item tag (FFFE,{:04X}) at byte {}", element, pos);
            if ((!endsItem && !endsSequence) || frames.back().end)
                return fmt::format("a delimiter (FFFE,{:04X}) at byte {} outside a sequence or item of undefined length it could end", element, pos);
            // GDCM reads the delimiter that ends encapsulated pixel data as
            // one more fragment and allocates its length before reading it
            // (Fragment::ReadValue: 2 GB for a 1,601-byte file, found by
            // fuzz_scan_headers); DICOM gives every delimiter a length of 0.
            if (endsSequence && where == Kind::Fragments && length != 0)
                return fmt::format("the delimiter (FFFE,E0DD) at byte {} that ends encapsulated pixel data claims {} bytes (DICOM gives it 0)", pos, length);
            if (const std::string bad = leave(); !bad.empty()) return bad;
            pos += header;
            continue;
        }
        if (where == Kind::Sequence || where == Kind::Fragments)
            return fmt::format("an element ({:04X},{:04X}) at byte {} where an item belongs", group, element, pos);
        const char vr[3] = {char(h[4]), char(h[5]), 0};
        // GDCM asserts (aborts) on a meta group element whose VR is not one of DICOM's.
        static const std::set<std::string> knownVr{"AE", "AS", "AT", "CS", "DA", "DS", "DT", "FD", "FL", "IS", "LO", "LT", "OB", "OD", "OF",
                                                   "OL", "OV", "OW", "PN", "SH", "SL", "SQ", "SS", "ST", "SV", "TM", "UC", "UI", "UL", "UN",
                                                   "UR", "US", "UT", "UV"};
        if (inMeta && !knownVr.count(vr)) return fmt::format("file meta element ({:04X},{:04X}) at byte {} has no valid VR", group, element, pos);
        // Nor on one of VR SQ: the file meta group holds no sequence, and
        // GDCM asserts on one there (ReadExplicitDataElement,
        // gdcmFileMetaInformation.cxx; a (0002,0001) SQ of length 0 after
        // the DICM prefix: found by fuzz_scan_headers).
        if (inMeta && std::strcmp(vr, "SQ") == 0)
            return fmt::format("file meta element ({:04X},{:04X}) at byte {} is a sequence (VR SQ), which the file meta group never holds", group, element, pos);
        // An implicit transfer syntax is read as implicit (as GDCM does).
        // Under an explicit one, an element without a VR is refused: GDCM
        // guesses how to read such an element, and a 462-byte file whose
        // guessed length GDCM allocated took 1.7 GB (found by
        // fuzz_scan_headers; the walk had read it as implicit). Only a data
        // set without a file meta group to declare its syntax, whose first
        // element's VR bytes are no VR, is read as implicit, as GDCM guesses
        // it. Under a syntax the file meta group declares explicit, GDCM
        // reads such a first element and those after it with a 2-byte
        // length after the 2 bytes where the VR belongs
        // (VR16ExplicitDataElement), not as implicit, and asserted when the
        // file ended after such a tag and VR (a 506-byte RLE file the walk
        // had read as implicit: found by fuzz_scan_headers).
        if (!inMeta && !declaredImplicit) {
            const bool known = knownVr.count(vr) > 0;
            if (!datasetStarted && !known && !declaredSyntax) declaredImplicit = true, explicitVr = false;
            else if (!known)
                return declaredSyntax ? fmt::format("element ({:04X},{:04X}) at byte {} has no valid VR under the explicit transfer syntax {} its file meta group declares",
                                                    group, element, pos, transferSyntax)
                                      : fmt::format("element ({:04X},{:04X}) at byte {} has no valid VR under an explicit transfer syntax", group, element, pos);
            else explicitVr = true;
        }
        if (!inMeta) datasetStarted = true;
        // An element GDCM's image reader reads with another VR than its own
        // (kReaderVrs): GDCM asserts on it.
        if (!inMeta && explicitVr)
            if (const std::string bad = readerVrProblem(group, element, vr, pos); !bad.empty()) return bad;
        if (inMeta || explicitVr) {
            static const std::set<std::string> longVr{"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV"};
            if (longVr.count(vr)) {
                if (!readAt(pos, h, 12)) return fmt::format("element ({:04X},{:04X}) at byte {} is cut off", group, element, pos);
                // Two reserved bytes follow these VRs; GDCM asserts that they are zero (gdcmVR16ExplicitDataElement.txx:117).
                if (h[6] != 0 || h[7] != 0)
                    return fmt::format("element ({:04X},{:04X}) at byte {} has non-zero reserved bytes after its VR {}", group, element, pos, vr);
                length = le ? uint32_t(h[8]) | uint32_t(h[9]) << 8 | uint32_t(h[10]) << 16 | uint32_t(h[11]) << 24 : u32(h + 8);
                header = 12;
            } else {
                length = le ? uint16_t(h[6] | h[7] << 8) : u16(h + 6);
                header = 8;
            }
        } else {
            length = u32(h + 4);
            header = 8;
        }
        if (inMeta && length == 0xFFFFFFFFu)  // GDCM asserts on it too
            return fmt::format("file meta element ({:04X},{:04X}) at byte {} has an undefined length", group, element, pos);
        // GDCM reads an element of undefined length as a sequence when its
        // explicit VR is SQ or UN, as fragments when it is Pixel Data of VR
        // OB, OW or UN, and asserts on any other VR
        // (ExplicitDataElement::ReadValue, gdcmExplicitDataElement.txx:203
        // and :210: an "OD" of undefined length, found by fuzz_scan_headers).
        if (!inMeta && explicitVr && length == 0xFFFFFFFFu) {
            const bool pixels = group == kPixelGroup && element == 0x0010;
            const bool readable = std::strcmp(vr, "UN") == 0 || (pixels ? std::strcmp(vr, "OB") == 0 || std::strcmp(vr, "OW") == 0 : std::strcmp(vr, "SQ") == 0);
            if (!readable)
                return fmt::format("element ({:04X},{:04X}) at byte {} has an undefined length under VR {} (GDCM takes it for {} only)", group, element, pos,
                                   vr, pixels ? "OB, OW or UN pixel data" : "a sequence of VR SQ or UN");
        }
        const bool pixelData = group == kPixelGroup && element == 0x0010 && frames.size() == 1;
        // Under an explicit transfer syntax GDCM reads the pixel data's own
        // VR even when it stops there, and asserts on one it cannot read as
        // OB/OW-like (a VR such as "O\xF7" and non-zero reserved bytes).
        if (pixelData && !declaredImplicit && !explicitVr)
            return fmt::format("the pixel data at byte {} has no valid VR under an explicit transfer syntax", pos);
        if (beforePixels && pixelData) return "";
        if (pixels && pixelData && !pixels->found) {
            pixels->found = true;
            pixels->encapsulated = length == 0xFFFFFFFFu;
            pixels->offset = pos + header;
            pixels->length = pixels->encapsulated ? 0 : length;
            pixels->bigEndian = bigEndian;
            pixels->transferSyntax = transferSyntax;
        }
        if (where == Kind::Item && length != 0xFFFFFFFFu && length % 2) {
            frames.back().odd = !frames.back().odd;
            frames.back().oddAt = {group, element, pos, length};
        }
        if (length == 0xFFFFFFFFu) {  // a sequence or encapsulated pixel data: walk into it
            pos += header;
            if (const std::string bad = enter(group == kPixelGroup && element == 0x0010 ? Kind::Fragments : Kind::Sequence, pos, length); !bad.empty())
                return bad;
            continue;
        }
        if (length > size - pos - header) {
            if (pixelLength && group == kPixelGroup && element == 0x0010) *pixelLength = length;
            return fmt::format("element ({:04X},{:04X}) at byte {} claims {} bytes, but only {} follow", group, element, pos, length, size - pos - header);
        }
        // The transfer syntax as GDCM reads it: the first (0002,0010), its
        // value up to its first NUL, less trailing spaces, however long the
        // element (the walk had skipped one of 276 bytes, "1.2.840.10008.1.2.5"
        // and a NUL before other bytes, that GDCM read as RLE: found by
        // fuzz_scan_headers).
        if (inMeta && element == 0x0010 && !declaredSyntax) {
            constexpr uint64_t kMaxUid = 64 * 1024;
            std::string uid(std::min(length, kMaxUid), '\0');
            if (!readAt(pos + header, uid.data(), uid.size())) return fmt::format("element (0002,0010) at byte {} is cut off", pos);
            const size_t nul = uid.find('\0');
            if (nul == std::string::npos && length > kMaxUid)
                return fmt::format("its transfer syntax (0002,0010) at byte {} is {} bytes long", pos, length);
            if (nul != std::string::npos) uid.resize(nul);
            while (!uid.empty() && uid.back() == ' ') uid.pop_back();
            transferSyntax = uid;
            declaredSyntax = true;
        }
        // An explicit SQ of defined length: GDCM reads its items, so the walk does.
        if ((inMeta || explicitVr) && std::string(vr) == "SQ" && length > 0) {
            pos += header;
            if (const std::string bad = enter(Kind::Sequence, pos, length); !bad.empty()) return bad;
            continue;
        }
        pos += header + length;
    }
    // A file that ends inside a sequence, an item or encapsulated pixel
    // data, whatever it starts with: GDCM asserts on it (8 bytes, a Pixel
    // Data tag of undefined length and nothing after it, aborted in
    // BasicOffsetTable::Read: found by fuzz_scan_headers).
    if (frames.size() > 1)
        return fmt::format("the file ends inside a sequence or item (at byte {} of {})", pos, size);
    // A file that ends inside its file meta group (GDCM asserts on it).
    if (metaGroup) return fmt::format("the file ends inside its file meta group (at byte {} of {})", pos, size);
    return "";
}

} // namespace

std::string elementLengthProblem(const std::string& path, bool beforePixels, uint64_t* pixelLength, DicomPixelData* pixels) {
    bool unknownStart = false;
    if (pixels) *pixels = DicomPixelData{};
    const std::string problem = walkElementLengths(path, beforePixels, pixelLength, unknownStart, pixels);
    // What starts like no DICOM and does not walk as one is not DICOM.
    if (!problem.empty() && unknownStart) return "not a DICOM file (no DICM preamble, and " + problem + ")";
    return problem;
}

} // namespace vdbdag::bridge::detail
