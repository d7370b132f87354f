// Lossless (and near-lossless) coding of a 3-D block of integer samples:
// a causal 3-D neighbourhood, four predictors blended by their recent local
// errors, bias correction and an adaptive binary range coder whose models
// are chosen by the local activity. The coding layer of values at rest
// (issue "smaller than JPEG-LS"); docs/CODING.md describes the stream.
//
// Samples are visited in raster order (x fastest, then y, then z). Each is
// predicted from the already coded neighbours
//      this slice:  NW N NE        previous slice:  PNW PN
//                   W  *                            PW  P
// by four predictors:
//   MED   the median edge detector of JPEG-LS on W, N, NW (edges in-plane);
//   3-D   Lorenzo's plane through the 2x2x2 cube: W + N + P - NW - PW - PN + PNW
//         (smooth volumes, gradients along z);
//   SLICE P + MED(W, N, NW) - MED(PW, PN, PNW): the previous slice moved by
//         the in-plane change (structures that continue across slices);
//   DIAG  W + NE - N (edges running diagonally in-plane).
// Each predictor's absolute error is kept per sample; the blend weights
// each by 2^24 / (1 + its errors at W, N, NE and P), integers only, so the
// result is the same on every machine. The blend is clamped to the range of
// W, N, NE and P, then corrected by the mean residual of its context.
//
// Context: the final residuals' magnitudes at W, N, NE and P, summed and
// bucketed by bit length (24 buckets): it predicts how large this residual
// will be, so each bucket's models learn their own distribution.
// Residual coding under a context: a zero flag, a sign, the magnitude's bit
// length in unary (adaptive bits per position), then the bits below the
// leading one (the two highest adaptive per length, the rest per position).
//
// Near-lossless (near > 0, JPEG-LS NEAR): the residual is quantised to
// multiples of 2 near + 1 inside the loop, so every reconstructed sample is
// within `near` of the original and the decoder predicts from the same
// reconstructed values.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vdbdag::coding {

struct IntVolumeShape {
    int64_t nx = 0, ny = 0, nz = 0;
    uint64_t count() const { return uint64_t(nx) * uint64_t(ny) * uint64_t(nz); }
};

// The newest model generation (SamplePredictor.h), what a writer writes.
inline constexpr int kLatestIntModel = 4;

struct IntCoderOptions {
    // Every sample and every reconstruction lies in [minValue, maxValue]
    // (the sample type's range: 0..4095 for 12-bit CT).
    int64_t minValue = INT32_MIN, maxValue = INT32_MAX;
    // 0: lossless; n > 0: |decoded - original| <= n for every sample.
    int32_t near = 0;
    // The model's generation (SamplePredictor.h): 0, bias correction per
    // activity context (window codings 2-4 of files written before 2026-12-05);
    // 1, per activity context and texture (codings 5 and 6); 2, the least-
    // squares fit and the floor flag (codings 10 and 11, written
    // 2026-12-05 to 2026-12-06); 3, the fit over 24 neighbours, solved every
    // 64 samples, and the activity over WW, NN, NEE too (codings 13 and 14,
    // coding 12's generation 1, written on 2026-12-06); 4, the residual's
    // models and the bias corrections also by the prediction's intensity
    // band (codings 15 and 16, coding 12's generation 2, and this coder).
    int model = kLatestIntModel;
    // A placed walk of generation 4 with tiles as neighbours (window coding
    // 19, PlacedWalk.h's kTiles): a voxel beside a tile up to 32^3 sees its
    // value there, where coding 15's walk sees none. Tiles themselves are
    // coded as before (from the entry before).
    bool tileNeighbours = false;
    // Encoding only, and only its speed: the range coding runs on a thread
    // of its own beside the walk (CodeAside.h; the same
    // bytes). For an encoder that may use one more thread than it runs on.
    bool codeAside = false;
    // Generations 3 and 4, the raster coder (encodeIntVolume, decodeIntVolume)
    // and the placed walk (BrickValueCoder.h's encodePlacedBrickValues;
    // window codings 21 and 22): the volume before this one in a series (a
    // 4-D scan's volume t - 1; shape.count() samples in raster order, or the
    // entries of the same layout in the same order), which encoder and
    // decoder both hold. Its samples at the same (x, y, z) and one step back along
    // x, y and z are four neighbours of the least-squares fit, in place of
    // WWWW, NWWW, NEEE and NNN (LeastSquaresPredictor.h). The fit weighs
    // them as it finds them: the 25 ASL volumes of mpld_asl.nii.gz
    // (64x64x24) cost 808,884 bytes coded alone and 564,350 each with the
    // one before as its reference (-30 %); volumes of independent noise
    // around one mean, -2 %. Empty: none. Near-lossless (near > 0): the
    // reference must be the previous volume as the decoder rebuilds it
    // (encodeIntVolume's `reconstructed`), or the two drift apart.
    std::span<const int32_t> reference;
};

// Codes `samples` (shape.count() of them, raster order). With near > 0,
// `reconstructed` (if given) receives what the decoder will produce.
// Throws vdbdag::Error when a sample lies outside [minValue, maxValue].
std::vector<uint8_t> encodeIntVolume(std::span<const int32_t> samples, IntVolumeShape shape, const IntCoderOptions& options,
                                     std::vector<int32_t>* reconstructed = nullptr);

// Decodes into `out` (shape.count() samples). Throws vdbdag::Error naming
// `what` when the stream ends early or carries bytes it does not use
// (corrupt); never reads outside `bytes`, and its time is bounded by the
// sample count.
void decodeIntVolume(std::span<const uint8_t> bytes, IntVolumeShape shape, const IntCoderOptions& options, std::span<int32_t> out,
                     const std::string& what = "value stream");

} // namespace vdbdag::coding
