// See DicomSequence.h. The walk follows GDCM 3.0's implicit VR readers
// (SequenceOfItems::Read, Item::Read, DataSet::Read/ReadWithLength,
// ImplicitDataElement::ReadPreValue/ReadValue) as far as lengths go: an
// item is (FFFE,E000) and a 4-byte length, undefined (it ends at
// (FFFE,E00D)) or the bytes of its elements; an element is a tag and a
// 4-byte length, undefined for a sequence (for Pixel Data, fragments whose
// lengths are allocated). An item tag read as (FEFF,00E0) or (FEFF,DDE0)
// takes GDCM's branch for Philips files of the other byte order: its length
// and elements are read byte-swapped (each tag number and length
// big-endian).
#include "vdb_bridge/detail/DicomSequence.h"

#include <fmt/core.h>
#include <gdcmByteValue.h>

#include <cstring>
#include <optional>
#include <span>

namespace vdbdag::bridge::detail {
namespace {

constexpr uint32_t kUndefined = 0xFFFFFFFFu;

// GDCM's implicit VR reading of the bytes.
struct Attempt {
    std::span<const uint8_t> bytes;
    bool swap = false;  // inside a Philips item of the other byte order
    // What stopped it: a length past the bytes larger than kMaxUnheldBytes
    // (GDCM allocates it), or anything else GDCM throws on.
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
            const uint32_t len = u32(pos + 4);
            pos += 8;
            if (len == kUndefined && group == 0x7FE0 && element == 0x0010) {  // pixel data fragments: each item's length is allocated
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
            if (len == kUndefined) {  // a sequence
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
    const gdcm::VR vr = de.GetVR();
    const bool un = vr == gdcm::VR::UN;
    if (vr != gdcm::VR::INVALID && !un && !(vr & gdcm::VR::OB_OW)) return "";  // GDCM does not parse it
    const std::string stored = fmt::format("a sequence stored as {} bytes ({})", bytes.size(), un ? "UN" : vr == gdcm::VR::INVALID ? "implicit VR" : gdcm::VR::GetVRString(vr));
    // GDCM's first attempt, implicit VR little endian (what DICOM CP-246
    // asks of a sequence stored as UN): walked, bounded by the bytes.
    Attempt a{bytes};
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
