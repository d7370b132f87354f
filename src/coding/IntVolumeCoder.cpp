// See IntVolumeCoder.h. One template walks the samples for both
// directions, so the encoder and the decoder cannot drift apart: only the
// residual step differs (code it, or read it).
#include "src/coding/IntVolumeCoder.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <memory>
#include <string>

#include "src/coding/RangeCoder.h"
#include "src/coding/CodingLoop.h"
#include "src/coding/SamplePredictor.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

// Generations 2's and 3's far neighbours (LeastSquaresPredictor.h) of sample
// i at (x, y, z), each with the nearest near neighbour where the volume ends.
// `ref`, `refBelow`: this slice and the one below of the reference volume
// (IntCoderOptions::reference), or null.
inline void farNeighbours(Neighbourhood& n, int64_t x, int64_t y, int64_t z, int64_t nx, int64_t ny, size_t i, const std::vector<int64_t>& cur,
                          const std::vector<int64_t>& prev, const std::vector<int64_t>& prev2, const int32_t* ref, const int32_t* refBelow) {
    const size_t row = size_t(nx);
    const bool hx = x > 0, hy = y > 0, hz = z > 0, hE = x + 1 < nx, hS = y + 1 < ny;
    n.far[kWW] = x > 1 ? cur[i - 2] : n.W;
    n.far[kNN] = y > 1 ? cur[i - 2 * row] : n.N;
    n.far[kPP] = z > 1 ? prev2[i] : n.P;
    n.far[kPE] = hz && hE ? prev[i + 1] : n.P;
    n.far[kPS] = hz && hS ? prev[i + row] : n.P;
    n.far[kPNE] = hz && hE && hy ? prev[i - row + 1] : hz ? n.PN : n.P;
    n.far[kPSW] = hz && hS && hx ? prev[i + row - 1] : hz ? n.PW : n.P;
    n.far[kPSE] = hz && hS && hE ? prev[i + row + 1] : n.far[kPS];
    n.far[kNWW] = x > 1 && hy ? cur[i - row - 2] : n.NW;
    n.far[kNNE] = y > 1 && hE ? cur[i - 2 * row + 1] : n.far[kNN];
    n.far[kNNW] = y > 1 && hx ? cur[i - 2 * row - 1] : n.far[kNN];
    n.far[kNEE] = x + 2 < nx && hy ? cur[i - row + 2] : n.NE;
    n.far[kWWW] = x > 2 ? cur[i - 3] : n.far[kWW];
    n.far[kWWWW] = x > 3 ? cur[i - 4] : n.far[kWWW];
    n.far[kNWWW] = x > 2 && hy ? cur[i - row - 3] : n.far[kNWW];
    n.far[kNEEE] = x + 3 < nx && hy ? cur[i - row + 3] : n.far[kNEE];
    n.far[kNNN] = y > 2 ? cur[i - 3 * row] : n.far[kNN];
    if (ref) {
        const int64_t t = ref[i];
        n.far[kNNN] = t;
        n.far[kWWWW] = hx ? ref[i - 1] : t;
        n.far[kNWWW] = hy ? ref[i - row] : t;
        n.far[kNEEE] = refBelow ? refBelow[i] : t;
    }
}

// The raster walk shared by both directions. `step(prediction, sample
// index)` returns the reconstructed sample.
template <typename Step>
void walk(IntVolumeShape shape, const IntCoderOptions& options, Models& models, Step&& step) {
    const int64_t nx = shape.nx, ny = shape.ny, nz = shape.nz;
    const size_t plane = size_t(nx) * size_t(ny);
    std::vector<int64_t> cur(plane), prev(plane), prev2(plane);  // this slice, the two below
    std::vector<SampleRecord> curRec(plane), prevRec(plane);
    const SampleRecord none{};
    // Per row, what the neighbours above and behind contribute to each
    // predictor's error sum (2 N + NE + NW + 2 P + PW + PN) and to the
    // activity (the same of the residuals): summed once per row, in a loop
    // the compiler vectorises; W's part is added per sample.
    std::vector<uint64_t> rowErrors(size_t(nx) * kPredictors);
    std::vector<uint64_t> rowResiduals(static_cast<size_t>(nx));
    const bool referenced = !options.reference.empty() && models.farActivity;  // generation 3 on: 24 taps
    for (int64_t z = 0; z < nz; ++z) {
        const int32_t* ref = referenced ? options.reference.data() + size_t(z) * plane : nullptr;
        const int32_t* refBelow = referenced && z > 0 ? ref - plane : nullptr;
        for (int64_t y = 0; y < ny; ++y) {
            for (int64_t x = 0; x < nx; ++x) {
                const size_t i = size_t(y * nx + x);
                const bool hx = x > 0, hy = y > 0, hz = z > 0, hne = hy && x + 1 < nx;
                const SampleRecord& rN = hy ? curRec[i - size_t(nx)] : none;
                const SampleRecord& rNE = hne ? curRec[i - size_t(nx) + 1] : none;
                const SampleRecord& rNW = hx && hy ? curRec[i - size_t(nx) - 1] : none;
                const SampleRecord& rP = hz ? prevRec[i] : none;
                const SampleRecord& rPW = hz && hx ? prevRec[i - 1] : none;
                const SampleRecord& rPN = hz && hy ? prevRec[i - size_t(nx)] : none;
                if (!models.leastSquares)  // generation 2 has no blend to weigh
                    for (size_t k = 0; k < kPredictors; ++k)
                        rowErrors[size_t(x) * kPredictors + k] = 2 * (uint64_t(rN.err[k]) + rP.err[k]) + rNE.err[k] + rNW.err[k] + rPW.err[k] + rPN.err[k];
                rowResiduals[size_t(x)] = 2 * (uint64_t(rN.residual) + rP.residual) + rNE.residual + rNW.residual + rPW.residual + rPN.residual;
            }
            for (int64_t x = 0; x < nx; ++x) {
                const size_t i = size_t(y * nx + x);
                // Neighbours, with the nearest coded one where the volume ends.
                const bool hx = x > 0, hy = y > 0, hz = z > 0, hne = hy && x + 1 < nx;
                Neighbourhood n;
                n.W = hx ? cur[i - 1] : hy ? cur[i - size_t(nx)] : hz ? prev[i] : 0;
                n.N = hy ? cur[i - size_t(nx)] : n.W;
                n.NW = hx && hy ? cur[i - size_t(nx) - 1] : n.N;
                n.NE = hne ? cur[i - size_t(nx) + 1] : n.N;
                if (hz) {
                    n.P = prev[i];
                    n.PW = hx ? prev[i - 1] : hy ? prev[i - size_t(nx)] : n.P;
                    n.PN = hy ? prev[i - size_t(nx)] : n.PW;
                    n.PNW = hx && hy ? prev[i - size_t(nx) - 1] : n.PN;
                } else {
                    n.P = med(n.W, n.N, n.NW), n.PW = n.W, n.PN = n.N, n.PNW = n.NW;
                }
                farNeighbours(n, x, y, z, nx, ny, i, cur, prev, prev2, ref, refBelow);
                n.rW = hx ? &curRec[i - 1] : nullptr;
                n.rN = hy ? &curRec[i - size_t(nx)] : nullptr;
                n.rP = hz ? &prevRec[i] : nullptr;
                std::copy_n(&rowErrors[size_t(x) * kPredictors], kPredictors, n.errorsAbove.begin());
                n.residualsAbove = rowResiduals[size_t(x)];
                if (models.farActivity)
                    n.residualsFar = uint64_t(x > 1 ? curRec[i - 2].residual : 0) + (y > 1 ? curRec[i - 2 * size_t(nx)].residual : 0) +
                                     (hy && x + 2 < nx ? curRec[i - size_t(nx) + 2].residual : 0);
                const Prediction pr = predict(n, options.minValue, options.maxValue, models);
                const int64_t value = step(pr, size_t(z) * plane + i);
                learn(pr, value, curRec[i]);
                cur[i] = value;
            }
        }
        std::swap(prev2, prev);
        std::swap(cur, prev);
        std::swap(curRec, prevRec);
    }
}

void checkShape(IntVolumeShape shape, const IntCoderOptions& options) {
    if (shape.nx < 0 || shape.ny < 0 || shape.nz < 0) throw Error("value coder: a negative extent");
    if (!options.reference.empty() && options.reference.size() != shape.count())
        throw Error("value coder: a reference volume of " + std::to_string(options.reference.size()) + " samples for " + std::to_string(shape.count()));
}

} // namespace

std::vector<uint8_t> encodeIntVolume(std::span<const int32_t> samples, IntVolumeShape shape, const IntCoderOptions& options,
                                     std::vector<int32_t>* reconstructed) {
    checkShape(shape, options);
    if (samples.size() != shape.count()) throw Error("value coder: " + std::to_string(samples.size()) + " samples for " + std::to_string(shape.count()));
    return encodeSamples(samples, options, reconstructed, [&](Models& models, auto&& step) { walk(shape, options, models, step); });
}

void decodeIntVolume(std::span<const uint8_t> bytes, IntVolumeShape shape, const IntCoderOptions& options, std::span<int32_t> out,
                     const std::string& what) {
    checkShape(shape, options);
    if (out.size() != shape.count()) throw Error(what + ": room for " + std::to_string(out.size()) + " samples, " + std::to_string(shape.count()) + " to decode");
    decodeSamples(bytes, options, out, what, [&](Models& models, auto&& step) { walk(shape, options, models, step); });
}

} // namespace vdbdag::coding
