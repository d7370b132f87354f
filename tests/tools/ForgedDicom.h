// Forged DICOM bytes shared by the hostile-input tests and the fuzz seed
// corpus (tests/fuzz/make_seed_corpus.cpp), written byte by byte so that
// neither depends on a DICOM library.
#pragma once
#include <cstdint>
#include <string>

namespace vdbdag::testing {

// An explicit VR little-endian DICOM file of one CT slice: the elements a
// series needs, in tag order, then `pixelBytes` of native pixel data
// (explicit VR: 2-byte lengths; OB/OW: 4-byte ones).
inline std::string forgedCtSlice(uint16_t rows, uint16_t cols, uint32_t pixelBytes) {
    std::string out(128, '\0');
    out += "DICM";
    auto element = [&](uint16_t g, uint16_t e, const char* vr, const std::string& value) {
        std::string v = value;
        if (v.size() % 2) v += std::string(vr) == "UI" ? '\0' : ' ';
        out.append(reinterpret_cast<const char*>(&g), 2).append(reinterpret_cast<const char*>(&e), 2).append(vr, 2);
        const bool longForm = std::string(vr) == "OB" || std::string(vr) == "OW";
        if (longForm) {
            const uint32_t n = uint32_t(v.size());
            out.append(2, '\0').append(reinterpret_cast<const char*>(&n), 4);
        } else {
            const uint16_t n = uint16_t(v.size());
            out.append(reinterpret_cast<const char*>(&n), 2);
        }
        out += v;
    };
    auto us = [](uint16_t v) { return std::string(reinterpret_cast<const char*>(&v), 2); };
    const std::string sop = "1.2.840.10008.5.1.4.1.1.2", instance = "1.2.3.4.5.6.7";
    element(0x0002, 0x0001, "OB", std::string("\0\1", 2));
    element(0x0002, 0x0002, "UI", sop);
    element(0x0002, 0x0003, "UI", instance);
    element(0x0002, 0x0010, "UI", "1.2.840.10008.1.2.1");
    element(0x0008, 0x0016, "UI", sop);
    element(0x0008, 0x0018, "UI", instance);
    element(0x0008, 0x0060, "CS", "CT");
    element(0x0020, 0x000d, "UI", "1.2.3.4.5.1");
    element(0x0020, 0x000e, "UI", "1.2.3.4.5.2");
    element(0x0020, 0x0032, "DS", "0\\0\\0");
    element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
    element(0x0028, 0x0002, "US", us(1));
    element(0x0028, 0x0004, "CS", "MONOCHROME2");
    element(0x0028, 0x0010, "US", us(rows));
    element(0x0028, 0x0011, "US", us(cols));
    element(0x0028, 0x0030, "DS", "1\\1");
    element(0x0028, 0x0100, "US", us(16));
    element(0x0028, 0x0101, "US", us(12));
    element(0x0028, 0x0102, "US", us(11));
    element(0x0028, 0x0103, "US", us(0));
    element(0x7fe0, 0x0010, "OW", std::string(pixelBytes, '\0'));
    return out;
}

} // namespace vdbdag::testing
