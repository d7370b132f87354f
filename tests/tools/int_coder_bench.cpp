// The integer value coder (src/coding/IntVolumeCoder) against JPEG-LS per
// slice (CharLS, the codec hospitals store CT and MR in), JPEG 2000
// lossless per slice (OpenJPEG), xz -9e and zstd -19, on the stored
// samples of a scan as vdbdag reads them (DICOM, NIfTI, NRRD, MetaImage,
// raw), in one run:
//
//   vdbdag_int_coder_bench SCAN [--near N] [--repeats R] [--series N] [--volume N] [--dump RAW]
//   vdbdag_int_coder_bench SCAN_4D --series-reference 1
//
// The second: each volume of a 4-D scan coded alone and with the volume
// before it as the coder's reference (IntCoderOptions::reference): the
// bytes of each way, summed, and every decode checked.
//
// `ours_model1_bytes`: the same volume coded with the previous model
// generation (the blend of six, SamplePredictor.h), once, for the table's
// "before" column.
//
// Both see the same samples: JPEG-LS each z-slice, min-subtracted, at the
// scan's own bit depth (the bits its value range needs, at least 2: 12 for
// most CT, 8 for 8-bit MR), as the issue measures it; ours the whole volume
// with the same range. Every decode is checked against the input (every
// sample exact, or within N). Timings alternate the two codecs R times and
// report medians. One JSON object on stdout.
#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <charls/charls.h>
#include <lzma.h>
#include <openjpeg.h>
#include <nlohmann/json.hpp>
#include <zstd.h>

#include "src/coding/IntVolumeCoder.h"
#include "src/util/Error.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/detail/DenseBricks.h"

#include "tests/tools/BenchTiming.h"

namespace {

using vdbdag::benchtools::Clock;
using vdbdag::benchtools::median;
using vdbdag::benchtools::seconds;

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
                case SampleType::F32: {  // float samples that are all integers (a series saved as float), as the import takes them
                    float x;
                    std::memcpy(&x, p, 4);
                    if (!vdbdag::bridge::detail::onIntegerLattice(x))
                        throw vdbdag::Error(v.headerPath + ": a float sample that is no integer (" + std::to_string(x) + "): the integer coder takes integers");
                    s = int32_t(x);
                    break;
                }
                default: throw vdbdag::Error(v.headerPath + ": " + vdbdag::bridge::sampleTypeName(v.type) + " samples: the integer coder takes 8- to 32-bit integers");
            }
            out.push_back(s);
        }
    }
    return out;
}

// --series-reference: each volume of a 4-D scan coded alone and with the
// volume before it as its reference (IntCoderOptions::reference), lossless,
// every decode checked. One JSON object.
nlohmann::json seriesReport(const std::string& path, vdbdag::bridge::DenseImportOptions options) {
    options.volume = 0;
    const int64_t volumes = vdbdag::bridge::describeDense(path, options).volumeCount;
    std::vector<std::vector<int32_t>> all;
    int32_t lo = INT32_MAX, hi = INT32_MIN;
    vdbdag::bridge::DenseVolume v;
    for (int64_t t = 0; t < volumes; ++t) {
        options.volume = t;
        v = vdbdag::bridge::describeDense(path, options);
        all.push_back(storedSamples(v));
        for (const int32_t s : all.back()) lo = std::min(lo, s), hi = std::max(hi, s);
    }
    const vdbdag::coding::IntVolumeShape shape{v.dims[0], v.dims[1], v.dims[2]};
    vdbdag::coding::IntCoderOptions o;
    o.minValue = lo, o.maxValue = hi;
    size_t alone = 0, referenced = 0, wrong = 0;
    std::vector<int32_t> back(shape.count());
    for (size_t t = 0; t < all.size(); ++t) {
        vdbdag::coding::IntCoderOptions r = o;
        const std::vector<uint8_t> own = vdbdag::coding::encodeIntVolume(all[t], shape, o);
        alone += own.size();
        vdbdag::coding::decodeIntVolume(own, shape, o, back);
        wrong += back != all[t];
        if (t > 0) r.reference = all[t - 1];
        const std::vector<uint8_t> bytes = vdbdag::coding::encodeIntVolume(all[t], shape, r);
        referenced += bytes.size();
        vdbdag::coding::decodeIntVolume(bytes, shape, r, back);
        wrong += back != all[t];  // volumes_wrong counts each way's failures
    }
    return {{"scan", path}, {"volumes", volumes}, {"dims", {shape.nx, shape.ny, shape.nz}}, {"alone_bytes", alone}, {"with_previous_bytes", referenced},
            {"ratio", double(referenced) / double(alone)}, {"volumes_wrong", wrong}};
}

} // namespace

// JPEG 2000 lossless (OpenJPEG, reversible 5/3, one quality layer) of one
// slice, through memory streams: its codestream's size, and whether it
// decodes back to the same samples.
struct MemoryStream {
    std::vector<uint8_t> data;
    size_t pos = 0;
};
OPJ_SIZE_T memoryWrite(void* buffer, OPJ_SIZE_T n, void* user) {
    auto* s = static_cast<MemoryStream*>(user);
    if (s->pos + n > s->data.size()) s->data.resize(s->pos + n);
    std::memcpy(s->data.data() + s->pos, buffer, n);
    s->pos += n;
    return n;
}
OPJ_SIZE_T memoryRead(void* buffer, OPJ_SIZE_T n, void* user) {
    auto* s = static_cast<MemoryStream*>(user);
    if (s->pos >= s->data.size()) return OPJ_SIZE_T(-1);
    n = std::min<OPJ_SIZE_T>(n, s->data.size() - s->pos);
    std::memcpy(buffer, s->data.data() + s->pos, n);
    s->pos += n;
    return n;
}
OPJ_OFF_T memorySkip(OPJ_OFF_T n, void* user) {
    static_cast<MemoryStream*>(user)->pos += size_t(n);
    return n;
}
OPJ_BOOL memorySeek(OPJ_OFF_T at, void* user) {
    static_cast<MemoryStream*>(user)->pos = size_t(at);
    return OPJ_TRUE;
}
opj_stream_t* memoryStream(MemoryStream& s, bool input) {
    opj_stream_t* st = opj_stream_create(1 << 16, input ? OPJ_TRUE : OPJ_FALSE);
    opj_stream_set_user_data(st, &s, nullptr);
    if (input) {
        opj_stream_set_user_data_length(st, s.data.size());
        opj_stream_set_read_function(st, memoryRead);
    } else {
        opj_stream_set_write_function(st, memoryWrite);
    }
    opj_stream_set_skip_function(st, memorySkip);
    opj_stream_set_seek_function(st, memorySeek);
    return st;
}

// Returns the codestream bytes; `same` tells whether it decoded exactly.
size_t jpeg2000Slice(const int32_t* slice, uint32_t nx, uint32_t ny, int bits, bool& same) {
    opj_cparameters_t p;
    opj_set_default_encoder_parameters(&p);
    p.tcp_numlayers = 1;
    p.tcp_rates[0] = 0;  // lossless
    p.cp_disto_alloc = 1;
    p.irreversible = 0;
    int levels = 1;
    while (levels < 6 && (std::min(nx, ny) >> levels) >= 8) ++levels;
    p.numresolution = levels;
    opj_image_cmptparm_t c{};
    c.dx = c.dy = 1, c.w = nx, c.h = ny, c.prec = OPJ_UINT32(bits), c.sgnd = 0;
    opj_image_t* image = opj_image_create(1, &c, OPJ_CLRSPC_GRAY);
    image->x0 = image->y0 = 0, image->x1 = nx, image->y1 = ny;
    std::copy_n(slice, size_t(nx) * ny, image->comps[0].data);
    MemoryStream out;
    opj_codec_t* codec = opj_create_compress(OPJ_CODEC_J2K);
    opj_stream_t* st = memoryStream(out, false);
    const bool ok = opj_setup_encoder(codec, &p, image) && opj_start_compress(codec, image, st) && opj_encode(codec, st) && opj_end_compress(codec, st);
    opj_stream_destroy(st);
    opj_destroy_codec(codec);
    opj_image_destroy(image);
    if (!ok) throw vdbdag::Error("OpenJPEG could not encode a slice");
    MemoryStream in{out.data, 0};
    opj_dparameters_t d;
    opj_set_default_decoder_parameters(&d);
    codec = opj_create_decompress(OPJ_CODEC_J2K);
    st = memoryStream(in, true);
    opj_image_t* back = nullptr;
    same = opj_setup_decoder(codec, &d) && opj_read_header(st, codec, &back) && opj_decode(codec, st, back) && opj_end_decompress(codec, st) &&
           back->numcomps == 1 && back->comps[0].w == nx && back->comps[0].h == ny && std::equal(slice, slice + size_t(nx) * ny, back->comps[0].data);
    opj_stream_destroy(st);
    opj_destroy_codec(codec);
    if (back) opj_image_destroy(back);
    return out.data.size();
}

int main(int argc, char** argv) {
    try {
        if (argc < 2) throw vdbdag::Error("usage: vdbdag_int_coder_bench SCAN [--near N] [--repeats R] [--series N] [--volume N] [--dump RAW] | SCAN_4D --series-reference 1");
        const std::string path = argv[1];
        int near = 0, repeats = 3;
        std::string dump;  // --dump PATH: the stored samples as raw int32 (x fastest), then stop
        bool seriesReference = false;
        vdbdag::bridge::DenseImportOptions options;
        options.showProgress = false;
        for (int i = 2; i + 1 < argc; i += 2) {
            const std::string flag = argv[i], value = argv[i + 1];
            if (flag == "--near") near = std::stoi(value);
            else if (flag == "--repeats") repeats = std::max(1, std::stoi(value));
            else if (flag == "--series") options.series = value;
            else if (flag == "--volume") options.volume = std::stoll(value);
            else if (flag == "--dump") dump = value;
            else if (flag == "--series-reference" && value == "1") seriesReference = true;
            else throw vdbdag::Error("unknown option " + flag);
        }
        if (seriesReference) {
            const nlohmann::json r = seriesReport(path, options);
            std::printf("%s\n", r.dump().c_str());
            return r["volumes_wrong"] == 0 ? 0 : 1;
        }
        const vdbdag::bridge::DenseVolume v = vdbdag::bridge::describeDense(path, options);
        const std::vector<int32_t> samples = storedSamples(v);
        const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end());
        const int32_t minValue = *lo, maxValue = *hi;
        int bits = 2;
        while ((int64_t(1) << bits) - 1 < int64_t(maxValue) - minValue) ++bits;
        if (bits > 16) throw vdbdag::Error(path + ": a " + std::to_string(bits) + "-bit range; JPEG-LS takes at most 16 bits");
        const int64_t nx = v.dims[0], ny = v.dims[1], nz = v.dims[2];
        if (!dump.empty()) {
            std::FILE* f = std::fopen(dump.c_str(), "wb");
            if (!f || std::fwrite(samples.data(), sizeof(int32_t), samples.size(), f) != samples.size() || std::fclose(f) != 0)
                throw vdbdag::Error(dump + ": cannot write the samples");
            std::printf("{\"dims\": [%lld, %lld, %lld], \"min\": %d, \"max\": %d}\n", (long long)nx, (long long)ny, (long long)nz, minValue, maxValue);
            return 0;
        }
        const size_t plane = size_t(nx * ny);

        vdbdag::coding::IntCoderOptions o;
        o.minValue = minValue, o.maxValue = maxValue, o.near = near;
        const vdbdag::coding::IntVolumeShape shape{nx, ny, nz};
        vdbdag::coding::IntCoderOptions model1 = o;
        model1.model = 1;
        const size_t model1Bytes = vdbdag::coding::encodeIntVolume(samples, {nx, ny, nz}, model1).size();
        vdbdag::coding::IntCoderOptions model2 = o;  // the generation before ours, timed in the same loop
        model2.model = vdbdag::coding::kLatestIntModel - 1;
        std::vector<double> oursEncode, oursDecode, jlsEncode, jlsDecode, model2Encode, model2Decode;
        size_t oursBytes = 0, jlsBytes = 0, oursWrong = 0, jlsWrong = 0, model2Bytes = 0;
        for (int r = 0; r < repeats; ++r) {
            {  // generation 2
                auto t0 = Clock::now();
                const std::vector<uint8_t> coded = vdbdag::coding::encodeIntVolume(samples, shape, model2);
                auto t1 = Clock::now();
                std::vector<int32_t> back(samples.size());
                vdbdag::coding::decodeIntVolume(coded, shape, model2, back);
                model2Encode.push_back(seconds(t0, t1));
                model2Decode.push_back(seconds(t1, Clock::now()));
                model2Bytes = coded.size();
                for (size_t i = 0; i < samples.size(); ++i) oursWrong += std::abs(int64_t(back[i]) - samples[i]) > near;
            }
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
        // General-purpose peers, lossless only: xz -9e and zstd -19 of the
        // whole volume's samples as JPEG-LS gets them (min-subtracted, 1 or 2
        // bytes little-endian), each checked by decompressing.
        size_t xzBytes = 0, zstdBytes = 0, j2kBytes = 0, j2kWrong = 0;
        double xzEncode = 0, zstdEncode = 0, j2kSeconds = 0;
        if (near == 0) {
            const size_t bytesPerSample = bits <= 8 ? 1 : 2;
            std::vector<uint8_t> raw(samples.size() * bytesPerSample);
            for (size_t i = 0; i < samples.size(); ++i) {
                const uint32_t s = uint32_t(samples[i] - minValue);
                if (bytesPerSample == 1) raw[i] = uint8_t(s);
                else { const uint16_t x = uint16_t(s); std::memcpy(&raw[2 * i], &x, 2); }
            }
            auto a = Clock::now();
            std::vector<uint8_t> z(ZSTD_compressBound(raw.size()));
            zstdBytes = ZSTD_compress(z.data(), z.size(), raw.data(), raw.size(), 19);
            auto b = Clock::now();
            if (ZSTD_isError(zstdBytes)) throw vdbdag::Error("zstd failed");
            std::vector<uint8_t> zback(raw.size());
            if (ZSTD_decompress(zback.data(), zback.size(), z.data(), zstdBytes) != raw.size() || zback != raw) throw vdbdag::Error("zstd round trip failed");
            std::vector<uint8_t> x(lzma_stream_buffer_bound(raw.size()));
            auto c = Clock::now();
            if (lzma_easy_buffer_encode(9 | LZMA_PRESET_EXTREME, LZMA_CHECK_CRC64, nullptr, raw.data(), raw.size(), x.data(), &xzBytes, x.size()) != LZMA_OK)
                throw vdbdag::Error("xz failed");
            auto d = Clock::now();
            std::vector<uint8_t> xback(raw.size());
            uint64_t memlimit = UINT64_MAX;
            size_t inPos = 0, outPos = 0;
            if (lzma_stream_buffer_decode(&memlimit, 0, nullptr, x.data(), &inPos, xzBytes, xback.data(), &outPos, xback.size()) != LZMA_OK || xback != raw)
                throw vdbdag::Error("xz round trip failed");
            zstdEncode = seconds(a, b), xzEncode = seconds(c, d);
            // JPEG 2000 lossless, each z-slice (min-subtracted, the scan's bit depth), once.
            std::vector<int32_t> slice(plane);
            auto e = Clock::now();
            for (int64_t z = 0; z < nz; ++z) {
                for (size_t i = 0; i < plane; ++i) slice[i] = samples[size_t(z) * plane + i] - minValue;
                bool same = false;
                j2kBytes += jpeg2000Slice(slice.data(), uint32_t(nx), uint32_t(ny), bits, same);
                j2kWrong += !same;
            }
            j2kSeconds = seconds(e, Clock::now());
        }
        const double mb = double(samples.size() * (bits <= 8 ? 1 : 2)) / 1e6;  // MB of samples at the scan's bit depth
        const nlohmann::json report{{"scan", path},
                                    {"dims", {nx, ny, nz}},
                                    {"bits", bits},
                                    {"near", near},
                                    {"ours_bytes", oursBytes},
                                    {"ours_model1_bytes", model1Bytes},
                                    {"previous_model", model2.model},
                                    {"ours_model2_bytes", model2Bytes},
                                    {"ours_model2_encode_mb_s", mb / median(model2Encode)},
                                    {"ours_model2_decode_mb_s", mb / median(model2Decode)},
                                    {"jpegls_bytes", jlsBytes},
                                    {"ratio", double(oursBytes) / double(jlsBytes)},
                                    {"ours_samples_wrong", oursWrong},
                                    {"jpegls_samples_wrong", jlsWrong},
                                    {"ours_encode_mb_s", mb / median(oursEncode)},
                                    {"ours_decode_mb_s", mb / median(oursDecode)},
                                    {"jpegls_encode_mb_s", mb / median(jlsEncode)},
                                    {"jpegls_decode_mb_s", mb / median(jlsDecode)},
                                    {"xz_bytes", xzBytes},
                                    {"zstd_bytes", zstdBytes},
                                    {"xz_encode_mb_s", xzBytes ? mb / xzEncode : 0.0},
                                    {"zstd_encode_mb_s", zstdBytes ? mb / zstdEncode : 0.0},
                                    {"jpeg2000_bytes", j2kBytes},
                                    {"jpeg2000_slices_wrong", j2kWrong},
                                    {"jpeg2000_encode_decode_mb_s", j2kBytes ? mb / j2kSeconds : 0.0},
                                    {"repeats", repeats}};
        std::printf("%s\n", report.dump().c_str());
        return oursWrong || jlsWrong || j2kWrong ? 1 : 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vdbdag_int_coder_bench: %s\n", e.what());
        return 2;
    }
}
