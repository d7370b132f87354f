// See DicomFileHeader.h.
#include "vdb_bridge/detail/DicomFileHeader.h"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <fmt/core.h>

#include <gdcmDataSet.h>
#include <gdcmMediaStorage.h>
#include <gdcmPhotometricInterpretation.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>
#include <gdcmUIDs.h>

#include "src/util/Error.h"
#include "vdb_bridge/DicomTags.h"
#include "vdb_bridge/detail/DicomElementWalk.h"
#include "vdb_bridge/detail/DicomSequence.h"

namespace vdbdag::bridge::detail {

namespace fs = std::filesystem;

void quietGdcm() {
    static const bool done = [] {
        gdcm::Trace::DebugOff();
        gdcm::Trace::WarningOff();
        gdcm::Trace::ErrorOff();
        return true;
    }();
    (void)done;
}

std::string trim(std::string s) {
    const auto junk = [](char c) { return c == ' ' || c == '\0' || c == '\t' || c == '\r' || c == '\n'; };
    while (!s.empty() && junk(s.back())) s.pop_back();
    size_t i = 0;
    while (i < s.size() && junk(s[i])) ++i;
    return s.substr(i);
}

std::optional<std::vector<double>> parseNumbers(const std::string& text) {
    std::vector<double> out;
    if (trim(text).empty()) return out;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t end = std::min(text.find('\\', start), text.size());
        std::string item = trim(text.substr(start, end - start));
        if (!item.empty() && item[0] == '+') item.erase(0, 1);
        double v = 0;
        const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
        if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(v)) return std::nullopt;
        out.push_back(v);
        start = end + 1;
    }
    return out;
}

namespace {

// The first item of sequence (group, element) in `ds`, or null; null with
// `problem` set where GDCM must not parse the sequence's bytes
// (DicomSequence.h).
const gdcm::DataSet* firstItem(const gdcm::DataSet& ds, uint16_t group, uint16_t element, gdcm::SmartPointer<gdcm::SequenceOfItems>& keep,
                               std::string& problem) {
    const gdcm::Tag tag(group, element);
    if (!ds.FindDataElement(tag)) return nullptr;
    keep = valueAsSequence(ds.GetDataElement(tag), problem);
    if (!keep || keep->GetNumberOfItems() < 1) return nullptr;
    return &keep->GetItem(1).GetNestedDataSet();
}

std::string sopClassName(const std::string& uid) {
    gdcm::UIDs u;
    if (!uid.empty() && u.SetFromUID(uid.c_str()) && u.GetName()) return std::string(u.GetName()) + " (" + uid + ")";
    return uid.empty() ? std::string("no SOP Class UID") : uid;
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// A SOP class that is not a greyscale image stack however it looks.
std::string nonImageClass(const std::string& sop) {
    if (sop == "1.2.840.10008.5.1.4.1.1.66.4") return "a DICOM-SEG segmentation object, not an image series";
    if (startsWith(sop, "1.2.840.10008.5.1.4.1.1.88.")) return "a structured report (SR), not an image";
    if (startsWith(sop, "1.2.840.10008.5.1.4.1.1.11.")) return "a presentation state, not an image";
    if (startsWith(sop, "1.2.840.10008.5.1.4.1.1.104.")) return "an encapsulated document, not an image";
    if (startsWith(sop, "1.2.840.10008.5.1.4.1.1.481.") && sop != "1.2.840.10008.5.1.4.1.1.481.1" && sop != "1.2.840.10008.5.1.4.1.1.481.2")
        return "a radiotherapy object (" + sopClassName(sop) + "), not an image";
    if (sop == "1.2.840.10008.5.1.4.1.1.66" || startsWith(sop, "1.2.840.10008.5.1.4.1.1.66."))
        return "a non-image object (" + sopClassName(sop) + ")";
    if (sop == "1.2.840.10008.1.3.10") return "a DICOMDIR (media directory), not an image";
    return "";
}

// The SOP class GDCM's image reader decodes a file as, when that is no image
// class (it asserts MediaStorage::IsImage then, PixmapReader::Read): where
// the file meta header's class is no image class (unknown, or known and
// another kind) and the data set's is unknown or missing, under a transfer
// syntax other than ACR-NEMA's, the reader guesses with
// MediaStorage::SetFromFile, which cuts a UID at its first space
// ("1.2.840.10008.3.1.2.3.1 .2" became Detached Study Management; found by
// fuzz_scan_headers). "" when the reader takes an image class or refuses the
// file itself (a DICOMDIR, a class both name alike).
std::string imageReaderClassProblem(const gdcm::File& file) {
    const gdcm::MediaStorage header = file.GetHeader().GetMediaStorage();
    if (gdcm::MediaStorage::IsImage(header)) return "";
    if (file.GetDataSet().GetMediaStorage() != gdcm::MediaStorage::MS_END) return "";  // GDCM reads it as an image class or refuses it
    if (header == gdcm::MediaStorage::MediaStorageDirectoryStorage) return "";     // GDCM refuses a DICOMDIR
    if (file.GetHeader().GetDataSetTransferSyntax() == gdcm::TransferSyntax::ImplicitVRBigEndianACRNEMA || file.GetHeader().IsEmpty())
        return "";  // read as ACR-NEMA
    gdcm::MediaStorage guess;
    guess.SetFromFile(file);
    if (guess == gdcm::MediaStorage::MS_END || gdcm::MediaStorage::IsImage(guess)) return "";
    return fmt::format("GDCM's image reader would take its SOP class for {} ({}), which is no image storage (it aborts on such a file)",
                       guess.GetString() ? guess.GetString() : "?", gdcm::MediaStorage::GetMSString(guess) ? gdcm::MediaStorage::GetMSString(guess) : "?");
}

// What GDCM 3.0's image reader (PixmapReader::ReadImageInternal, which
// vdbdag runs on a file whose pixel data it does not read itself: any but
// native pixel data under a native transfer syntax) asserts (aborts) or
// crashes on in the values of the overlay (60xx) and curve (50xx) groups
// and of the Icon Image Sequence (0088,0200); "" when none. The element
// walk has checked their VRs (kReaderVrs); these need their values, read
// here as GDCM keeps them (raw bytes, little-endian: no big-endian data set
// reaches that reader).
uint16_t valueUs(const gdcm::ByteValue& bv, size_t index) {
    const auto* p = reinterpret_cast<const uint8_t*>(bv.GetPointer()) + 2 * index;
    return uint16_t(p[0] | p[1] << 8);
}

std::string tagName(uint16_t group, uint16_t element) { return fmt::format("({:04X},{:04X})", group, element); }

// The overlay groups, as PixmapReader's GetNumberOfOverlaysInternal and
// DoOverlays and Overlay::Update read them. `nativePixels`: the pixel data
// are not encapsulated; `pixelBits`, `samplesPerPixel`: the image's Bits
// Allocated and Samples per Pixel.
std::string overlayProblem(const gdcm::DataSet& ds, bool nativePixels, unsigned pixelBits, unsigned samplesPerPixel) {
    std::map<uint16_t, std::vector<const gdcm::DataElement*>> groups;  // the even (public) groups 6000-60FE
    for (const gdcm::DataElement& de : ds.GetDES()) {
        const uint16_t g = de.GetTag().GetGroup();
        if (g > 0x60FF) break;
        if (g >= 0x6000 && g % 2 == 0) groups[g].push_back(&de);
    }
    const auto present = [&](uint16_t g, uint16_t e) { return ds.FindDataElement(gdcm::Tag(g, e)) && !ds.GetDataElement(gdcm::Tag(g, e)).IsEmpty(); };
    // What GDCM counts as an overlay: a group with Overlay Data, not empty;
    // or without it, with Rows, Columns and Bit Position, none empty.
    std::vector<uint16_t> overlays;
    for (const auto& [g, elements] : groups)
        if (ds.FindDataElement(gdcm::Tag(g, 0x3000)) ? present(g, 0x3000) : present(g, 0x0010) && present(g, 0x0011) && present(g, 0x0102))
            overlays.push_back(g);
    // GetNumberOfOverlaysInternal asserts that there are at most 16.
    if (overlays.size() > 16)
        return fmt::format("{} overlay groups (60xx), more than the 16 GDCM's image reader takes (it aborts on more)", overlays.size());
    int withData = -1, inPixels = -1;  // an overlay group of each kind (the last met)
    for (const uint16_t g : overlays) {
        unsigned rows = 0, columns = 0;
        bool data = false;
        for (const gdcm::DataElement* de : groups[g]) {
            const gdcm::ByteValue* bv = de->GetByteValue();
            if (!bv || !bv->GetLength()) continue;  // Update skips an empty element (and a sequence)
            const uint16_t e = de->GetTag().GetElement();
            const std::string s(bv->GetPointer(), bv->GetLength());
            static const std::set<uint16_t> known{0x0000, 0x0010, 0x0011, 0x0015, 0x0022, 0x0040, 0x0045, 0x0050, 0x0051, 0x0060,
                                                  0x0100, 0x0102, 0x0110, 0x0200, 0x1301, 0x1302, 0x1303, 0x1500, 0x3000};
            if (!known.count(e))
                return fmt::format("overlay group {:04X} holds element {}, which GDCM's image reader aborts on (Overlay::Update takes only the {} overlay "
                                   "elements it knows)",
                                   g, tagName(g, e), known.size());
            if (e == 0x0060 && s != "NONE")
                return fmt::format("element {} Overlay Compression Code is '{}', which GDCM's image reader aborts on (it takes NONE only)", tagName(g, e), s);
            if (e == 0x0110 && s != "RECT")
                return fmt::format("element {} Overlay Format is '{}', which GDCM's image reader aborts on (it takes RECT only)", tagName(g, e), s);
            // Attribute<0x6000,0x0050> (SS, VM 2) reads its two values and
            // asserts when the first is cut short.
            if (e == 0x0050 && bv->GetLength() < 2)
                return fmt::format("element {} Overlay Origin holds {} byte, too few for the first of its 2 values: GDCM's image reader aborts on it",
                                   tagName(g, e), uint32_t(bv->GetLength()));
            if (e == 0x0010) rows = bv->GetLength() >= 2 ? valueUs(*bv, 0) : uint8_t(s[0]);
            if (e == 0x0011) columns = bv->GetLength() >= 2 ? valueUs(*bv, 0) : uint8_t(s[0]);
            if (e == 0x3000) data = true;
        }
        const uint64_t pixels = uint64_t(rows) * columns;
        // DoOverlays unpacks every overlay (Overlay::Decompress) at a byte a
        // pixel into a string stream, whatever its Overlay Data holds: 65535 x
        // 65535 would take 4 GB and more while it grows.
        if (pixels > (uint64_t(1) << 26))
            return fmt::format("overlay group {:04X} of {}x{} pixels, which GDCM's image reader unpacks at a byte a pixel ({} MB; vdbdag takes overlays "
                               "of up to 2^26 pixels)",
                               g, rows, columns, pixels >> 20);
        // An overlay without Overlay Data (or of no pixels): GDCM takes it
        // from the unused bits of native pixel data of 8 or 16 bits of one
        // sample (Overlay::GrabOverlayFromPixelData), asserting that its
        // pixels are a multiple of 8.
        if ((!data || pixels == 0) && nativePixels && samplesPerPixel == 1 && (pixelBits == 8 || pixelBits == 16) && pixels % 8 != 0)
            return fmt::format("overlay group {:04X} of {}x{} pixels (not a multiple of 8) lies in the pixel data's unused bits, which GDCM's image reader "
                               "aborts on",
                               g, rows, columns);
        (data && pixels != 0 ? withData : inPixels) = g;
    }
    // DoOverlays takes an overlay whose Overlay Data it did not keep (none,
    // or no Rows x Columns to size it: Overlay::SetOverlay) to lie in the
    // pixel data's unused bits; Pixmap::AreOverlaysInPixelData then asserts
    // that all overlays do or none does. (GDCM may drop such an overlay
    // first, for a Bit Position below Bits Stored: refused all the same.)
    if (withData >= 0 && inPixels >= 0)
        return fmt::format("overlay group {:04X} keeps its Overlay Data and overlay group {:04X} does not (none, or no Rows x Columns to hold it), "
                           "so it lies in the pixel data's unused bits: GDCM's image reader aborts on the mix",
                           withData, inPixels);
    return "";
}

// The curve groups, as PixmapReader's DoCurves and Curve::Update read them:
// once one even 50xx group holds Curve Data, GDCM reads every even 50xx
// group as a curve, asserting that each holds Curve Data too, and that
// Update knows each element.
std::string curveProblem(const gdcm::DataSet& ds) {
    std::map<uint16_t, std::vector<const gdcm::DataElement*>> groups;
    for (const gdcm::DataElement& de : ds.GetDES()) {
        const uint16_t g = de.GetTag().GetGroup();
        if (g > 0x50FF) break;
        if (g >= 0x5000 && g % 2 == 0) groups[g].push_back(&de);
    }
    const auto withData = [&](uint16_t g) { return ds.FindDataElement(gdcm::Tag(g, 0x3000)) && !ds.GetDataElement(gdcm::Tag(g, 0x3000)).IsEmpty(); };
    if (std::none_of(groups.begin(), groups.end(), [&](const auto& kv) { return withData(kv.first); })) return "";
    for (const auto& [g, elements] : groups) {
        if (!withData(g))
            return fmt::format("curve group {:04X} has no Curve Data ({:04X},3000) while another curve group has, which GDCM's image reader aborts on", g,
                               g);
        for (const gdcm::DataElement* de : elements) {
            const gdcm::ByteValue* bv = de->GetByteValue();
            if (!bv || !bv->GetLength()) continue;
            const uint16_t e = de->GetTag().GetElement();
            static const std::set<uint16_t> known{0x0000, 0x0005, 0x0010, 0x0020, 0x0022, 0x0030, 0x0040, 0x0103, 0x0104,
                                                  0x0105, 0x0106, 0x0110, 0x0112, 0x0114, 0x2500, 0x2600, 0x2610, 0x3000};
            if (!known.count(e))
                return fmt::format("curve group {:04X} holds element {}, which GDCM's image reader aborts on (Curve::Update takes only the {} curve elements "
                                   "it knows)",
                                   g, tagName(g, e), known.size());
        }
    }
    return "";
}

// The first item of the Icon Image Sequence, as PixmapReader's DoIconImage
// reads it: its Photometric Interpretation, and for PALETTE COLOR its
// palette (gdcm::LookupTable::Allocate, InitializeLUT and SetLUT, and the
// reader's own check of each table's length), emulated here.
std::string iconProblem(const gdcm::DataSet& ds) {
    gdcm::SmartPointer<gdcm::SequenceOfItems> keep;
    const std::string where = "its Icon Image Sequence (0088,0200)";
    std::string problem;
    const gdcm::DataSet* icon = firstItem(ds, 0x0088, 0x0200, keep, problem);
    if (!problem.empty()) return where + " is " + problem;
    if (!icon) return "";
    // DoIconImage gives the icon's Samples per Pixel to
    // PixelFormat::SetSamplesPerPixel, which asserts on any but 1, 3 and 4
    // (79: found by fuzz_scan_headers).
    if (icon->FindDataElement(gdcm::Tag(0x0028, 0x0002)))
        if (const gdcm::ByteValue* bv = icon->GetDataElement(gdcm::Tag(0x0028, 0x0002)).GetByteValue(); bv && bv->GetLength()) {
            const unsigned spp = bv->GetLength() >= 2 ? valueUs(*bv, 0) : uint8_t(bv->GetPointer()[0]);
            if (spp != 1 && spp != 3 && spp != 4)
                return fmt::format("{} has Samples per Pixel (0028,0002) {}, which GDCM's image reader aborts on (it takes 1, 3 or 4)", where, spp);
        }
    gdcm::PhotometricInterpretation::PIType pi = gdcm::PhotometricInterpretation::MONOCHROME2;
    if (icon->FindDataElement(gdcm::Tag(0x0028, 0x0004))) {
        const gdcm::ByteValue* bv = icon->GetDataElement(gdcm::Tag(0x0028, 0x0004)).GetByteValue();
        // DoIconImage reads the value without asking whether there is one.
        if (!bv) return where + " has an empty Photometric Interpretation (0028,0004), which GDCM's image reader crashes on";
        pi = gdcm::PhotometricInterpretation::GetPIType(std::string(bv->GetPointer(), bv->GetLength()).c_str());
    }
    if (pi != gdcm::PhotometricInterpretation::PALETTE_COLOR) return "";
    if (icon->FindDataElement(gdcm::Tag(0x0028, 0x1221)))
        return where + " holds a segmented palette (0028,1221), which GDCM's image reader aborts on";
    unsigned bits = 0;  // Attribute<0x0028,0x0100> = {0}
    if (icon->FindDataElement(gdcm::Tag(0x0028, 0x0100)))
        if (const gdcm::ByteValue* bv = icon->GetDataElement(gdcm::Tag(0x0028, 0x0100)).GetByteValue(); bv && bv->GetLength())
            bits = bv->GetLength() >= 2 ? valueUs(*bv, 0) : uint8_t(bv->GetPointer()[0]);
    if (bits != 8 && bits != 16)
        return fmt::format("{} is PALETTE COLOR with Bits Allocated {}, which GDCM's image reader aborts on (its palettes take 8 or 16)", where, bits);
    const size_t rgbSize = bits == 8 ? 256 * 3 : 65536 * 2 * 3;
    uint32_t lutLength[3] = {0, 0, 0};
    unsigned lutBits[3] = {0, 0, 0};
    bool incomplete = false;
    static const char* const colour[3] = {"Red", "Green", "Blue"};
    for (unsigned i = 0; i < 3; ++i) {
        const uint16_t descriptor = uint16_t(0x1101 + i), data = uint16_t(0x1201 + i), segmented = uint16_t(0x1221 + i);
        const std::string name = fmt::format("{} Palette Color Lookup Table Descriptor {}", colour[i], tagName(0x0028, descriptor));
        // Element<VR::US,VM::VM3>: left undefined without a value, asserts
        // on fewer than 2 values, leaves the third undefined without it.
        const gdcm::ByteValue* d = icon->FindDataElement(gdcm::Tag(0x0028, descriptor)) ? icon->GetDataElement(gdcm::Tag(0x0028, descriptor)).GetByteValue()
                                                                                         : nullptr;
        if (!d || d->GetLength() < 6)
            return fmt::format("{} has a {} of {} bytes, fewer than its 3 values: GDCM's image reader aborts on it or reads undefined ones", where, name,
                               d ? uint32_t(d->GetLength()) : 0u);
        const unsigned entries = valueUs(*d, 0), first = valueUs(*d, 1), entryBits = valueUs(*d, 2);
        if (entryBits == 8 || entryBits == 16) {  // LookupTable::InitializeLUT
            if (first != 0)
                return fmt::format("{} has a {} whose first mapped value is {}, which GDCM's image reader aborts on (it takes 0 only)", where, name, first);
            lutLength[i] = entries ? entries : 65536;
            lutBits[i] = entryBits;
            if (entries && entries != 256) incomplete = true;
        }
        const bool plain = icon->FindDataElement(gdcm::Tag(0x0028, data));
        if (!plain && !icon->FindDataElement(gdcm::Tag(0x0028, segmented))) return "";  // GDCM gives the icon up
        const uint16_t table = plain ? data : segmented;
        const gdcm::ByteValue* t = icon->GetDataElement(gdcm::Tag(0x0028, table)).GetByteValue();
        const std::string tableName = fmt::format("{} Palette Color Lookup Table Data {}", colour[i], tagName(0x0028, table));
        if (!t) return fmt::format("{} has an empty {}, which GDCM's image reader aborts on", where, tableName);
        const uint64_t length = uint32_t(t->GetLength());
        // LookupTable::SetLUT's asserts.
        bool fits = true;
        if (const uint64_t n = lutLength[i]) {
            if (!incomplete && rgbSize != 3 * n * (bits / 8)) fits = false;
            else if (bits == 8) {
                const uint64_t mult = lutBits[i] / 8, mult2 = length / n;
                if (n * mult2 != length || n > 256) fits = false;
                else if (n * mult == length || n * mult + 1 == length) fits = mult2 == 1 || mult2 == 2;
                else fits = mult2 == 2;
            } else {
                fits = n * 2 == length;
            }
        }
        // DoIconImage's check of a (not segmented) table's length.
        if (plain) {
            const uint64_t check = uint64_t(entries ? entries : 65536) * entryBits / 8;
            if (check != length && 2 * check != length && check + 1 != length) fits = false;
        }
        if (!fits)
            return fmt::format("{} has a {} of {} bytes, which its descriptor ({}, {}, {}) and Bits Allocated {} do not fit: GDCM's image reader aborts on it",
                               where, tableName, length, entries, first, entryBits, bits);
    }
    return "";
}


} // namespace

std::string readFile(const std::string& path, FileInfo& info, std::vector<Frame>& frames) {
    quietGdcm();
    if (const std::string bad = elementLengthProblem(path, true); !bad.empty())
        return bad.rfind("not a DICOM file", 0) == 0 ? bad : "corrupt DICOM: " + bad;
    gdcm::Reader reader;
    reader.SetFileName(path.c_str());
    // GDCM reads the element it stops at: the pixel data are skipped, not
    // loaded (their length is checked below).
    if (!reader.ReadUpToTag(gdcm::Tag(kPixelGroup, 0x0008), {gdcm::Tag(kPixelGroup, 0x0010)})) return "not a DICOM file (or unreadable)";
    const gdcm::File& file = reader.GetFile();
    const gdcm::DataSet& ds = file.GetDataSet();
    const Fields f(file);
    std::string sop = f.text(ds, 0x0008, 0x0016);
    if (sop.empty()) sop = trim(f.text(file.GetHeader(), 0x0002, 0x0002));
    if (const std::string why = nonImageClass(sop); !why.empty()) return why;
    // The retired Recognition Code of ACR-NEMA files: GDCM's image reader
    // asserts (aborts) on one that does not start as theirs did (found by
    // fuzz_scan_headers: "1.2.3.4.5.6.7" in an RLE file).
    if (ds.FindDataElement(gdcm::Tag(0x0008, 0x0010))) {
        const std::string code = trim(f.text(ds, 0x0008, 0x0010));
        if (!startsWith(code, "ACR-NEMA") && !startsWith(code, "ACRNEMA") && !startsWith(code, "MIPS 2.0"))
            return "corrupt DICOM: its Recognition Code (0008,0010) '" + code + "' is none an ACR-NEMA file has";
    }
    const auto rows = f.numbers(ds, 0x0028, 0x0010), cols = f.numbers(ds, 0x0028, 0x0011);
    if (!rows || !cols || rows->size() != 1 || cols->size() != 1 || (*rows)[0] < 1 || (*cols)[0] < 1)
        return "no image (no Rows/Columns; SOP class " + sopClassName(sop) + ")";
    info.rows = uint32_t((*rows)[0]);
    info.columns = uint32_t((*cols)[0]);

    // The pixel data element itself (the header read stops before it).
    uint64_t nativePixelBytes = 0;  // the length of native (not encapsulated) pixel data, else 0
    DicomPixelData px;              // where the element walk found the pixel data
    {
        gdcm::Reader pixels;
        pixels.SetFileName(path.c_str());
        const std::set<gdcm::Tag> tags{gdcm::Tag(kPixelGroup, 0x0008), gdcm::Tag(kPixelGroup, 0x0009), gdcm::Tag(kPixelGroup, 0x0010)};
        // A file whose header reads but whose pixel data does not is part of
        // its series all the same (damaged): the series is refused naming it,
        // rather than showing a gap.
        // GDCM would allocate a declared pixel length past the file's end
        // before reading it: such a file is damaged without asking GDCM.
        uint64_t declaredPixels = 0;
        const std::string bad = elementLengthProblem(path, false, &declaredPixels, &px);
        if (!bad.empty()) {
            const bool bigEndian = file.GetHeader().GetDataSetTransferSyntax() == gdcm::TransferSyntax::ExplicitVRBigEndian;
            if (declaredPixels) info.damaged = checkNativeLength(path, uint32_t(declaredPixels), bigEndian);
            if (info.damaged.empty()) info.damaged = "is corrupt: " + bad;
        }
        const bool read = bad.empty() && pixels.ReadSelectedTags(tags, false);
        const gdcm::DataSet& p = pixels.GetFile().GetDataSet();
        const gdcm::Tag pixelData(kPixelGroup, 0x0010);
        if (!bad.empty()) {
            // damaged, named above
        } else if (!read) {
            info.damaged = "is truncated or corrupt: its pixel data cannot be read";
        } else {
            if (p.FindDataElement(gdcm::Tag(kPixelGroup, 0x0008)) || p.FindDataElement(gdcm::Tag(kPixelGroup, 0x0009)))
                return "float or double pixel data (Float/Double Float Pixel Data) is not supported";
            if (!p.FindDataElement(pixelData)) return "no pixel data (SOP class " + sopClassName(sop) + ")";
            const gdcm::VL vl = p.GetDataElement(pixelData).GetVL();
            const bool bigEndian = file.GetHeader().GetDataSetTransferSyntax() == gdcm::TransferSyntax::ExplicitVRBigEndian;
            if (!vl.IsUndefined() && uint32_t(vl) > 0) info.damaged = checkNativeLength(path, uint32_t(vl), bigEndian);
            if (!vl.IsUndefined()) nativePixelBytes = uint32_t(vl);
        }
    }
    // GDCM's image reader decodes what vdbdag does not read itself (any but
    // native pixel data under a native transfer syntax, DicomSeries.cpp),
    // and asserts (aborts) on overlay, curve and icon values the walk cannot
    // see: such a file is refused here, before its pixel data are decoded.
    const std::string& syntax = px.transferSyntax;
    const bool nativeSyntax = syntax.empty() || syntax == "1.2.840.10008.1.2" || syntax == "1.2.840.10008.1.2.1" || syntax == "1.2.840.10008.1.2.2";
    if (info.damaged.empty() && !(px.found && !px.encapsulated && nativeSyntax)) {
        const auto spp = f.numbers(ds, 0x0028, 0x0002);
        const auto bits = f.numbers(ds, 0x0028, 0x0100);
        // (Deflated data sets are not walked: their pixel data are native.)
        std::string why = overlayProblem(ds, !px.encapsulated, bits && bits->size() == 1 ? unsigned((*bits)[0]) : 0,
                                         spp && spp->size() == 1 ? unsigned((*spp)[0]) : 1);
        // PixelFormat::SetSamplesPerPixel asserts on any but 1, 3 and 4; the
        // image reader takes the first value of a Samples per Pixel that
        // holds several (DICOM allows one).
        if (why.empty() && spp && spp->size() > 1)
            why = fmt::format("Samples per Pixel (0028,0002) holds {} values where DICOM has one (GDCM's image reader takes the first, {}, "
                              "and aborts on any but 1, 3 or 4)",
                              spp->size(), (*spp)[0]);
        if (why.empty() && spp && spp->size() == 1 && (*spp)[0] != 1 && (*spp)[0] != 3 && (*spp)[0] != 4)
            why = fmt::format("Samples per Pixel (0028,0002) {}, which GDCM's image reader aborts on (it takes 1, 3 or 4)", (*spp)[0]);
        if (why.empty()) why = imageReaderClassProblem(file);
        if (why.empty()) why = curveProblem(ds);
        if (why.empty()) why = iconProblem(ds);
        if (!why.empty()) return "corrupt DICOM: " + why;
    }

    info.file = path;
    info.seriesUid = f.text(ds, 0x0020, 0x000e);
    if (info.seriesUid.empty()) return "no Series Instance UID";
    info.modality = f.text(ds, 0x0008, 0x0060);
    info.description = f.text(ds, 0x0008, 0x103e);
    if (const auto n = f.numbers(ds, 0x0020, 0x0011); n && n->size() == 1) info.seriesNumber = int64_t((*n)[0]);
    const auto number = [&](uint16_t g, uint16_t e, unsigned fallback) {
        const auto v = f.numbers(ds, g, e);
        return v && v->size() == 1 && (*v)[0] >= 0 ? unsigned((*v)[0]) : fallback;
    };
    info.bitsAllocated = number(0x0028, 0x0100, 0);
    info.bitsStored = number(0x0028, 0x0101, 0);
    info.pixelRepresentation = number(0x0028, 0x0103, 0);
    info.samplesPerPixel = number(0x0028, 0x0002, 1);
    info.photometric = f.text(ds, 0x0028, 0x0004);
    info.tags = dicomTagsOf([&](uint16_t group, uint16_t element) { return f.text(ds, group, element); });

    // Geometry, rescale: from `where` (a functional group item or the top level).
    const auto readPlane = [&](const gdcm::DataSet* posDs, const gdcm::DataSet* oriDs, const gdcm::DataSet* pixDs, const gdcm::DataSet* resDs,
                               Frame& fr, bool& havePosition, bool& haveOrientation) -> std::string {
        if (posDs) {
            const auto p = f.numbers(*posDs, 0x0020, 0x0032);
            if (!p) return "unreadable Image Position (Patient)";
            if (p->size() == 3) { fr.position = {(*p)[0], (*p)[1], (*p)[2]}; havePosition = true; }
            else if (!p->empty()) return "Image Position (Patient) does not hold 3 numbers";
        }
        if (oriDs) {
            const auto o = f.numbers(*oriDs, 0x0020, 0x0037);
            if (!o) return "unreadable Image Orientation (Patient)";
            if (o->size() == 6) { std::copy(o->begin(), o->end(), fr.orientation.begin()); haveOrientation = true; }
            else if (!o->empty()) return "Image Orientation (Patient) does not hold 6 numbers";
        }
        if (pixDs) {
            auto s = f.numbers(*pixDs, 0x0028, 0x0030);
            if (!s || s->size() != 2) s = f.numbers(*pixDs, 0x0018, 0x1164);  // Imager Pixel Spacing
            if (s && s->size() == 2 && (*s)[0] > 0 && (*s)[1] > 0) {
                fr.rowSpacing = (*s)[0];
                fr.columnSpacing = (*s)[1];
                fr.pixelSpacingGiven = true;
            }
            if (const auto t = f.numbers(*pixDs, 0x0018, 0x0050); t && t->size() == 1 && (*t)[0] > 0) fr.thickness = (*t)[0];
        }
        if (resDs) {
            const auto a = f.numbers(*resDs, 0x0028, 0x1053), b = f.numbers(*resDs, 0x0028, 0x1052);
            if (!a || !b || a->size() > 1 || b->size() > 1) return "unreadable Rescale Slope/Intercept";
            if (a->size() == 1) fr.slope = (*a)[0];
            if (b->size() == 1) fr.intercept = (*b)[0];
        }
        return "";
    };

    Frame base;
    base.file = path;
    bool basePos = false, baseOri = false;
    if (std::string why = readPlane(&ds, &ds, &ds, &ds, base, basePos, baseOri); !why.empty()) return why;

    const auto nf = f.numbers(ds, 0x0028, 0x0008);
    const int64_t frameCount = nf && nf->size() == 1 && (*nf)[0] >= 1 ? int64_t((*nf)[0]) : 1;
    // Native pixel data must hold every pixel the header declares: a forged
    // 65535x65535 header over 64 bytes of pixels is damaged here, before a
    // reader reserves gigabytes for its slices.
    if (nativePixelBytes && info.damaged.empty() && info.bitsAllocated % 8 == 0) {
        const uint64_t need = uint64_t(info.rows) * info.columns * std::max(1u, info.samplesPerPixel) * (info.bitsAllocated / 8) * uint64_t(frameCount);
        if (nativePixelBytes < need)
            info.damaged = fmt::format("is damaged: its pixel data hold {} bytes, fewer than the {} its {} frame(s) of {}x{} pixels need", nativePixelBytes,
                                       need, frameCount, info.columns, info.rows);
    }
    gdcm::SmartPointer<gdcm::SequenceOfItems> sharedSq, perFrameSq;
    std::string problem;
    const gdcm::DataSet* shared = firstItem(ds, 0x5200, 0x9229, sharedSq, problem);
    if (!problem.empty()) return "corrupt DICOM: its Shared Functional Groups Sequence (5200,9229) is " + problem;
    if (ds.FindDataElement(gdcm::Tag(0x5200, 0x9230))) perFrameSq = valueAsSequence(ds.GetDataElement(gdcm::Tag(0x5200, 0x9230)), problem);
    if (!problem.empty()) return "corrupt DICOM: its Per-frame Functional Groups Sequence (5200,9230) is " + problem;

    if (perFrameSq && perFrameSq->GetNumberOfItems() > 0) {
        // Enhanced multi-frame: each frame's plane from its functional
        // groups, falling back on the shared ones.
        if (int64_t(perFrameSq->GetNumberOfItems()) != frameCount)
            return fmt::format("multi-frame file with {} frames but {} Per-frame Functional Groups items", frameCount, perFrameSq->GetNumberOfItems());
        for (int64_t k = 0; k < frameCount; ++k) {
            const gdcm::DataSet& item = perFrameSq->GetItem(size_t(k + 1)).GetNestedDataSet();
            Frame fr = base;
            fr.frame = uint32_t(k);
            fr.multiFrame = true;
            bool havePos = basePos, haveOri = baseOri;
            std::vector<gdcm::SmartPointer<gdcm::SequenceOfItems>> keep(8);
            std::string sequence;  // a functional group GDCM must not parse (DicomSequence.h)
            const auto group = [&](uint16_t g, uint16_t e, size_t slot) -> const gdcm::DataSet* {
                if (const gdcm::DataSet* d = firstItem(item, g, e, keep[slot], sequence)) return d;
                if (!sequence.empty()) return nullptr;
                return shared ? firstItem(*shared, g, e, keep[slot + 4], sequence) : nullptr;
            };
            const gdcm::DataSet* pos = group(0x0020, 0x9113, 0);
            const gdcm::DataSet* ori = sequence.empty() ? group(0x0020, 0x9116, 1) : nullptr;
            const gdcm::DataSet* pix = sequence.empty() ? group(0x0028, 0x9110, 2) : nullptr;
            const gdcm::DataSet* res = sequence.empty() ? group(0x0028, 0x9145, 3) : nullptr;
            if (!sequence.empty()) return fmt::format("corrupt DICOM: frame {}'s functional groups hold {}", k + 1, sequence);
            if (std::string why = readPlane(pos, ori, pix, res, fr, havePos, haveOri); !why.empty()) return fmt::format("frame {}: {}", k + 1, why);
            if (!havePos || !haveOri) return fmt::format("multi-frame file: frame {} has no Plane Position/Orientation", k + 1);
            frames.push_back(fr);
        }
        return "";
    }
    if (!basePos || !baseOri) return "no Image Position/Orientation (Patient) (SOP class " + sopClassName(sop) + "), so no place in a volume";
    if (frameCount == 1) {
        frames.push_back(base);
        return "";
    }
    // Multi-frame without per-frame positions: frames stepped along the
    // normal by Spacing Between Slices (or the RT Grid Frame Offset Vector).
    const Vec3 r{base.orientation[0], base.orientation[1], base.orientation[2]}, c{base.orientation[3], base.orientation[4], base.orientation[5]};
    Vec3 n = cross(r, c);
    const double nn = norm(n);
    if (!(nn > 0)) return "degenerate Image Orientation (Patient)";
    n = scaled(n, 1 / nn);
    std::vector<double> offsets;
    if (const auto sbs = f.numbers(ds, 0x0018, 0x0088); sbs && sbs->size() == 1 && (*sbs)[0] != 0) {
        for (int64_t k = 0; k < frameCount; ++k) offsets.push_back(double(k) * (*sbs)[0]);
    } else if (const auto g = f.numbers(ds, 0x3004, 0x000c); g && int64_t(g->size()) == frameCount) {
        offsets = *g;
    } else {
        return fmt::format("multi-frame file with {} frames but no per-frame positions (Per-frame Functional Groups) nor Spacing Between Slices; not supported",
                           frameCount);
    }
    for (int64_t k = 0; k < frameCount; ++k) {
        Frame fr = base;
        fr.frame = uint32_t(k);
        fr.multiFrame = true;
        for (int a = 0; a < 3; ++a) fr.position[size_t(a)] += offsets[size_t(k)] * n[size_t(a)];
        frames.push_back(fr);
    }
    return "";
}

std::vector<std::string> dicomdirFiles(const std::string& path, std::vector<std::string>& skipped) {
    quietGdcm();
    if (const std::string bad = elementLengthProblem(path); !bad.empty()) throw Error(path + ": corrupt DICOMDIR: " + bad);
    gdcm::Reader reader;
    reader.SetFileName(path.c_str());
    if (!reader.Read()) throw Error(path + ": not a readable DICOMDIR");
    const gdcm::File& file = reader.GetFile();
    const gdcm::DataSet& ds = file.GetDataSet();
    const Fields f(file);
    const gdcm::Tag records(0x0004, 0x1220);
    if (!ds.FindDataElement(records)) throw Error(path + ": a DICOMDIR without a Directory Record Sequence");
    std::string problem;
    const gdcm::SmartPointer<gdcm::SequenceOfItems> sq = valueAsSequence(ds.GetDataElement(records), problem);
    if (!problem.empty()) throw Error(path + ": its Directory Record Sequence (0004,1220) is " + problem);
    const fs::path folder = fs::path(path).parent_path();
    std::vector<std::string> out;
    std::set<std::string> seen;
    for (size_t i = 1; sq && i <= sq->GetNumberOfItems(); ++i) {
        const std::string id = f.text(sq->GetItem(i).GetNestedDataSet(), 0x0004, 0x1500);
        if (id.empty()) continue;
        fs::path p = folder;
        bool outside = false;
        size_t start = 0;
        while (start <= id.size()) {
            const size_t end = std::min(id.find('\\', start), id.size());
            const std::string part = trim(id.substr(start, end - start));
            if (part == ".." || part.find('/') != std::string::npos) outside = true;  // file IDs never leave the DICOMDIR's folder
            if (!part.empty() && !outside) {
                fs::path next = p / part;
                std::error_code ec;
                if (!fs::exists(next, ec)) {  // media file IDs are upper case; the disk may not be
                    for (const auto& e : fs::directory_iterator(p, ec)) {
                        std::string a = e.path().filename().string(), b = part;
                        std::transform(a.begin(), a.end(), a.begin(), [](unsigned char ch) { return char(std::toupper(ch)); });
                        std::transform(b.begin(), b.end(), b.begin(), [](unsigned char ch) { return char(std::toupper(ch)); });
                        if (a == b) { next = e.path(); break; }
                    }
                }
                p = next;
            }
            start = end + 1;
        }
        std::error_code ec;
        if (outside) {
            skipped.push_back(path + ": its file ID '" + id + "' leads out of its folder; not read");
            continue;
        }
        if (!fs::is_regular_file(p, ec)) {
            skipped.push_back(p.string() + ": listed in " + path + " but missing");
            continue;
        }
        if (seen.insert(p.string()).second) out.push_back(p.string());
    }
    return out;
}

} // namespace vdbdag::bridge::detail
