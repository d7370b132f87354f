// The integer value coder (src/coding/IntVolumeCoder) against JPEG-LS per
// slice (CharLS, the codec hospitals store CT and MR in), on the stored
// samples of a scan as vdbdag reads them (DICOM, NIfTI, NRRD, MetaImage,
// raw), in one run:
//
//   vdbdag_int_coder_bench SCAN [--near N] [--repeats R] [--series N] [--volume N]
//
// Both see the same samples: JPEG-LS each z-slice, min-subtracted, at the
// scan's own bit depth (the bits its value range needs, at least 2: 12 for
// most CT, 8 for 8-bit MR), as the issue measures it; ours the whole volume
// with the same range. Every decode is checked against the input (every
// sample exact, or within N). Timings alternate the two codecs R times and
// report medians. One JSON object on stdout.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <charls/charls.h>
#include <nlohmann/json.hpp>

#include "src/coding/IntVolumeCoder.h"
#include "src/util/Error.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DenseVolume.h"

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }
double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

std::vector<int32_t> storedSamples(const vdbdag::bridge::DenseVolume& v) {
    using vdbdag::bridge::SampleType;
    const std::unique_ptr<vdbdag::bridge::SliceReader> reader = vdbdag::bridge::openSliceReader(v);
    std::vector<int32_t> out;
    out.reserve(v.sampleCount());
    std::vector<uint8_t> slice;
    for (int64_t z = 0; z < v.dims[2]; ++z) {
        reader->readSlices(1, slice);
        const size_t n = size_t(v.sliceSamples());
        for (size_t i = 0; i < n; ++i) {
            const uint8_t* p = slice.data() + i * vdbdag::bridge::sampleBytes(v.type);
            int32_t s = 0;
            switch (v.type) {
                case SampleType::U8: s = *p; break;
                case SampleType::I8: s = int8_t(*p); break;
                case SampleType::U16: { uint16_t x; std::memcpy(&x, p, 2); s = x; break; }
                case SampleType::I16: { int16_t x; std::memcpy(&x, p, 2); s = x; break; }
                case SampleType::I32: std::memcpy(&s, p, 4); break;
                default: throw vdbdag::Error(v.headerPath + ": " + vdbdag::bridge::sampleTypeName(v.type) + " samples: the integer coder takes 8- to 32-bit integers");
            }
            out.push_back(s);
        }
    }
    return out;
}

} // namespace

int main(int argc, char** argv) {
    try {
        if (argc < 2) throw vdbdag::Error("usage: vdbdag_int_coder_bench SCAN [--near N] [--repeats R] [--series N] [--volume N]");
        const std::string path = argv[1];
        int near = 0, repeats = 3;
        vdbdag::bridge::DenseImportOptions options;
        options.showProgress = false;
        for (int i = 2; i + 1 < argc; i += 2) {
            const std::string flag = argv[i], value = argv[i + 1];
            if (flag == "--near") near = std::stoi(value);
            else if (flag == "--repeats") repeats = std::max(1, std::stoi(value));
            else if (flag == "--series") options.series = value;
            else if (flag == "--volume") options.volume = std::stoll(value);
            else throw vdbdag::Error("unknown option " + flag);
        }
        const vdbdag::bridge::DenseVolume v = vdbdag::bridge::describeDense(path, options);
        const std::vector<int32_t> samples = storedSamples(v);
        const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end());
        const int32_t minValue = *lo, maxValue = *hi;
        int bits = 2;
        while ((int64_t(1) << bits) - 1 < int64_t(maxValue) - minValue) ++bits;
        if (bits > 16) throw vdbdag::Error(path + ": a " + std::to_string(bits) + "-bit range; JPEG-LS takes at most 16 bits");
        const int64_t nx = v.dims[0], ny = v.dims[1], nz = v.dims[2];
        const size_t plane = size_t(nx * ny);

        vdbdag::coding::IntCoderOptions o;
        o.minValue = minValue, o.maxValue = maxValue, o.near = near;
        const vdbdag::coding::IntVolumeShape shape{nx, ny, nz};
        std::vector<double> oursEncode, oursDecode, jlsEncode, jlsDecode;
        size_t oursBytes = 0, jlsBytes = 0, oursWrong = 0, jlsWrong = 0;
        for (int r = 0; r < repeats; ++r) {
            // Ours: the whole volume.
            auto t0 = Clock::now();
            const std::vector<uint8_t> coded = vdbdag::coding::encodeIntVolume(samples, shape, o);
            auto t1 = Clock::now();
            std::vector<int32_t> back(samples.size());
            vdbdag::coding::decodeIntVolume(coded, shape, o, back);
            auto t2 = Clock::now();
            oursEncode.push_back(seconds(t0, t1));
            oursDecode.push_back(seconds(t1, t2));
            oursBytes = coded.size();
            oursWrong = 0;
            for (size_t i = 0; i < samples.size(); ++i) oursWrong += std::abs(int64_t(back[i]) - samples[i]) > near;
            // JPEG-LS: slice by slice.
            double enc = 0, dec = 0;
            jlsBytes = 0;
            jlsWrong = 0;
            const size_t bytesPerSample = bits <= 8 ? 1 : 2;
            std::vector<uint8_t> source(plane * bytesPerSample), decoded(plane * bytesPerSample);
            for (int64_t z = 0; z < nz; ++z) {
                for (size_t i = 0; i < plane; ++i) {
                    const uint32_t s = uint32_t(samples[size_t(z) * plane + i] - minValue);
                    if (bytesPerSample == 1) source[i] = uint8_t(s);
                    else { const uint16_t x = uint16_t(s); std::memcpy(&source[2 * i], &x, 2); }
                }
                auto a = Clock::now();
                charls::jpegls_encoder encoder;
                encoder.frame_info({uint32_t(nx), uint32_t(ny), bits, 1}).near_lossless(near);
                std::vector<uint8_t> destination(encoder.estimated_destination_size());
                encoder.destination(destination);
                const size_t size = encoder.encode(source);
                auto b = Clock::now();
                destination.resize(size);
                charls::jpegls_decoder::decode(destination, decoded);
                auto c = Clock::now();
                enc += seconds(a, b);
                dec += seconds(b, c);
                jlsBytes += size;
                for (size_t i = 0; i < plane; ++i) {
                    const int64_t got = bytesPerSample == 1 ? decoded[i] : int64_t(decoded[2 * i] | decoded[2 * i + 1] << 8);
                    jlsWrong += std::abs(got + minValue - samples[size_t(z) * plane + i]) > near;
                }
            }
            jlsEncode.push_back(enc);
            jlsDecode.push_back(dec);
        }
        const double mb = double(samples.size() * (bits <= 8 ? 1 : 2)) / 1e6;  // MB of samples at the scan's bit depth
        const nlohmann::json report{{"scan", path},
                                    {"dims", {nx, ny, nz}},
                                    {"bits", bits},
                                    {"near", near},
                                    {"ours_bytes", oursBytes},
                                    {"jpegls_bytes", jlsBytes},
                                    {"ratio", double(oursBytes) / double(jlsBytes)},
                                    {"ours_samples_wrong", oursWrong},
                                    {"jpegls_samples_wrong", jlsWrong},
                                    {"ours_encode_mb_s", mb / median(oursEncode)},
                                    {"ours_decode_mb_s", mb / median(oursDecode)},
                                    {"jpegls_encode_mb_s", mb / median(jlsEncode)},
                                    {"jpegls_decode_mb_s", mb / median(jlsDecode)},
                                    {"repeats", repeats}};
        std::printf("%s\n", report.dump().c_str());
        return oursWrong || jlsWrong ? 1 : 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vdbdag_int_coder_bench: %s\n", e.what());
        return 2;
    }
}
