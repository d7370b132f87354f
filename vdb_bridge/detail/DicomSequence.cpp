// See DicomSequence.h. The walk follows GDCM 3.0's readers
// (SequenceOfItems::Read, Item::Read, DataSet::Read/ReadWithLength,
// ImplicitDataElement and ExplicitDataElement::ReadPreValue/ReadValue) as
// far as lengths go: an item is (FFFE,E000) and a 4-byte length, undefined
// (it ends at (FFFE,E00D)) or the bytes of its elements; an implicit
// element is a tag and a 4-byte length, undefined for a sequence; an
// explicit one a tag, a VR and a 2-byte length, or 2 reserved bytes and a
// 4-byte one for OB, OD, OF, OL, OV, OW, SQ, SV, UC, UN, UR, UT and UV; a
// sequence's defined length holds its items. Byte-swapped, each tag number
// and length is read big-endian. An item tag read as (FEFF,00E0) or
// (FEFF,DDE0) takes GDCM's branch for Philips files of the other byte
// order (its length and elements byte-swapped: a second fuzz finding, an
// 800 MB allocation in the byte-swapped attempt at a little-endian item).
#include "vdb_bridge/detail/DicomSequence.h"

#include <fmt/core.h>
#include <gdcmByteValue.h>

#include <cstring>
#include <optional>
#include <span>

namespace vdbdag::bridge::detail {
namespace {

constexpr uint32_t kUndefined = 0xFFFFFFFFu;

// One of GDCM's attempts at the bytes.
struct Attempt {
    std::span<const uint8_t> bytes;
    bool explicitVr = false, swap = false;
    // What stopped it: a length past the bytes larger than kMaxUnheldBytes
    // (GDCM allocates it), or anything else GDCM throws on (it then tries
    // the next encoding).
    uint64_t tooLong = 0;
    size_t tooLongAt = 0;
    bool failed = false;

    uint16_t u16(size_t at) const {
        const uint16_t v = uint16_t(bytes[at] | bytes[at + 1] << 8);
        return swap ? uint16_t(v >> 8 | v << 8) : v;
    }
    uint32_t u32(size_t at) const {
        uint32_t v;
        std::memcpy(&v, bytes.data() + at, 4);
        return swap ? __builtin_bswap32(v) : v;
    }
    bool fail() {
        failed = true;
        return false;
    }
    // A declared length `len` at `at` against the `left` bytes it may take.
    bool fits(uint64_t len, size_t left, size_t at) {
        if (len <= left) return true;
        if (len > kMaxUnheldBytes) tooLong = len, tooLongAt = at;
        return fail();
    }

    // Items from `pos` to `end` (a sequence of defined length), or, with
    // `undefined`, up to and past the sequence delimiter (FFFE,E0DD): the
    // position after them, or nullopt where the attempt stops.
    std::optional<size_t> items(size_t pos, size_t end, bool undefined, int depth) {
        if (depth > 32) return fail(), std::nullopt;
        while (pos < end) {
            if (end - pos < 8) return fail(), std::nullopt;
            const uint16_t group = u16(pos), element = u16(pos + 2);
            const uint32_t len = u32(pos + 4);
            pos += 8;
            if (group == 0xFFFE && element == 0xE0DD) return pos;  // the sequence's end
            if (group == 0xFEFF && (element == 0x00E0 || element == 0xDDE0)) {
                // An item tag of the other byte order: GDCM's Philips branch
                // (Item::Read) takes it for the item (or the sequence's end),
                // reads its length byte-swapped whatever the attempt's order,
                // and its elements byte-swapped (an undefined length: then,
                // should that fail, as they are).
                if (element == 0xDDE0) return pos;
                uint32_t raw;
                std::memcpy(&raw, bytes.data() + pos - 4, 4);
                const uint32_t swapped = __builtin_bswap32(raw);
                const bool order = swap;
                swap = true;
                std::optional<size_t> after;
                if (swapped == kUndefined) {
                    after = elements(pos, end, true, depth + 1);
                    if (!after && !tooLong) {
                        failed = false;
                        swap = false;
                        after = elements(pos, end, true, depth + 1);
                    }
                } else {
                    const size_t itemEnd = swapped <= end - pos ? pos + swapped : end;
                    if (elements(pos, itemEnd, false, depth + 1)) {
                        if (itemEnd == pos + swapped) after = itemEnd;
                        else fail();
                    }
                }
                swap = order;
                if (!after) return std::nullopt;
                pos = *after;
                continue;
            }
            if (group != 0xFFFE || element != 0xE000) return fail(), std::nullopt;
            if (len == kUndefined) {
                const std::optional<size_t> after = elements(pos, end, true, depth + 1);
                if (!after) return std::nullopt;
                pos = *after;
            } else {
                // An item's length is no allocation: GDCM reads its elements
                // until the length or the bytes end (then fails).
                const size_t itemEnd = len <= end - pos ? pos + len : end;
                if (!elements(pos, itemEnd, false, depth + 1)) return std::nullopt;
                if (itemEnd != pos + len) return fail(), std::nullopt;
                pos = itemEnd;
            }
        }
        if (undefined) return fail(), std::nullopt;  // no delimiter
        return pos;
    }

    static bool longVr(const char* vr) {
        static const char* const kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV"};
        for (const char* l : kLong)
            if (vr[0] == l[0] && vr[1] == l[1]) return true;
        return false;
    }

    // An item's elements from `pos` to `end`, or with `undefined` up to and
    // past the item delimiter (FFFE,E00D).
    std::optional<size_t> elements(size_t pos, size_t end, bool undefined, int depth) {
        while (pos < end) {
            if (end - pos < 8) return fail(), std::nullopt;
            const uint16_t group = u16(pos), element = u16(pos + 2);
            if (group == 0xFFFE && element == 0xE00D) {
                pos += 8;
                if (undefined) return pos;
                continue;
            }
            uint32_t len = 0;
            bool sequence = false;
            if (!explicitVr) {
                len = u32(pos + 4);
                pos += 8;
                sequence = len == kUndefined;
                if (sequence && group == 0x7FE0 && element == 0x0010) {  // pixel data fragments: each item's length is allocated
                    while (true) {
                        if (end - pos < 8) return fail(), std::nullopt;
                        const uint16_t g = u16(pos), e = u16(pos + 2);
                        const uint32_t n = u32(pos + 4);
                        pos += 8;
                        if (g == 0xFFFE && e == 0xE0DD) break;
                        if (g != 0xFFFE || e != 0xE000 || !fits(n, end - pos, pos - 4)) return fail(), std::nullopt;
                        pos += n;
                    }
                    continue;
                }
            } else {
                const char vr[2] = {char(bytes[pos + 4]), char(bytes[pos + 5])};
                if (vr[0] < 'A' || vr[0] > 'Z' || vr[1] < 'A' || vr[1] > 'Z') return fail(), std::nullopt;
                if (longVr(vr)) {
                    if (end - pos < 12) return fail(), std::nullopt;
                    len = u32(pos + 8);
                    pos += 12;
                } else {
                    len = u16(pos + 6);
                    pos += 8;
                }
                const bool sq = vr[0] == 'S' && vr[1] == 'Q', un = vr[0] == 'U' && vr[1] == 'N';
                if (len == kUndefined) {
                    if (!sq && !un) return fail(), std::nullopt;
                    sequence = true;
                } else if (sq) {  // a sequence of defined length: its items (its length, like an item's, no allocation)
                    const size_t sqEnd = len <= end - pos ? pos + len : end;
                    if (!items(pos, sqEnd, false, depth + 1)) return std::nullopt;
                    if (sqEnd != pos + len) return fail(), std::nullopt;
                    pos = sqEnd;
                    continue;
                }
            }
            if (sequence) {
                const std::optional<size_t> after = items(pos, end, true, depth + 1);
                if (!after) return std::nullopt;
                pos = *after;
                continue;
            }
            if (!fits(len, end - pos, pos - 4)) return std::nullopt;
            pos += len;
        }
        if (undefined) return fail(), std::nullopt;
        return pos;
    }
};

} // namespace

std::string sequenceProblem(const gdcm::DataElement& de) {
    if (de.IsEmpty() || de.GetSequenceOfFragments() || dynamic_cast<const gdcm::SequenceOfItems*>(&de.GetValue())) return "";  // parsed already
    const gdcm::ByteValue* bv = de.GetByteValue();
    if (!bv || !bv->GetPointer()) return "";
    const std::span<const uint8_t> bytes(reinterpret_cast<const uint8_t*>(bv->GetPointer()), bv->GetLength());
    // GDCM's attempts for this VR, in its order (DataElement::GetValueAsSQ).
    struct Way {
        bool explicitVr, swap;
        const char* name;
    };
    const gdcm::VR vr = de.GetVR();
    const bool un = vr == gdcm::VR::UN;
    if (vr != gdcm::VR::INVALID && !un && !(vr & gdcm::VR::OB_OW)) return "";  // GDCM does not parse it
    const std::string stored = fmt::format("a sequence stored as {} bytes ({})", bytes.size(), un ? "UN" : vr == gdcm::VR::INVALID ? "implicit VR" : gdcm::VR::GetVRString(vr));
    // GDCM's first attempt, implicit VR little endian (what DICOM CP-246
    // asks of a sequence stored as UN): walked, bounded by the bytes.
    Attempt a{bytes, false, false};
    if (a.items(0, bytes.size(), false, 0)) return "";  // GDCM reads it so and stops
    if (a.tooLong)
        return fmt::format("{} that, read as implicit VR, declares {} bytes at its byte {}: GDCM would allocate them", stored, a.tooLong, a.tooLongAt);
    // Where that fails GDCM tries explicit VR, byte-swapped and as is (UN),
    // or byte-swapped (an implicit file's sequence whose first tag reads
    // (FEFF,00E0)), falling back on yet other readings inside (another
    // byte order for an item, implicit VR after a VR it does not know): a
    // walk of those cannot promise to follow it. Such a sequence is
    // refused; otherwise GDCM gives up on the bytes (no sequence).
    const bool philips = bytes.size() >= 4 && bytes[0] == 0xFF && bytes[1] == 0xFE && bytes[2] == 0xE0 && bytes[3] == 0x00;
    if (un || (vr == gdcm::VR::INVALID && philips))
        return stored + " that does not read as implicit VR little endian (DICOM CP-246): GDCM would read it in other byte orders and VRs, allocating "
                        "what they declare";
    return "";
}

gdcm::SmartPointer<gdcm::SequenceOfItems> valueAsSequence(const gdcm::DataElement& de, std::string& problem) {
    problem = sequenceProblem(de);
    if (!problem.empty()) return nullptr;
    return de.GetValueAsSQ();
}

} // namespace vdbdag::bridge::detail
