// Generations 2 and 3 of the integer value coders' prediction
// (SamplePredictor.h): a linear prediction from 19 (generation 2) or 24
// (generation 3) causal neighbours whose weights are the least-squares fit
// of the samples already coded, one fit per four activity contexts
// (SamplePredictor.h).
//
// Why: the blend of six fixed predictors (generations 0 and 1) cannot learn
// a scan's own correlations: an MR's smooth tissue wants most of its weight
// on the previous slice, a CT's streaks on the row above, a tooth's noise an
// average of many. A fit over the last few thousand samples of the same
// activity finds those weights; on the shared scans it codes 3-7 % smaller
// than the blend (docs/int_coder.md), at about twice the time.
//
// The neighbours, relative to W (so a constant offset costs nothing):
//      this slice:       NNN                 slice below:  PNW PN PNE     two below: PP
//                    NNW NN NNE                            PW  P  PE
//              NWWW  NWW NW N NE NEE NEEE                  PSW PS PSE
//        WWWW  WWW   WW  W  *
// Generation 3 adds WWWW, WWW, NWWW, NEEE and NNN (the last five above): an
// MR reconstructed from zero-padded k-space is smooth along its rows over
// more than two samples (adi_brain series 2: 2.6 % smaller; the other
// shared scans 0.2-2.6 %, but headsq, 64x64x93, 0.08 % larger:
// docs/int_coder.md).
// The slice below is wholly coded in raster order (IntVolumeCoder); the
// placed walk of a DAG's bricks has all but those in bricks not yet visited,
// and substitutes the nearest coded one (PlacedWalk.h).
//
// The fit: each fit sums x x^T and x y of its samples (x the neighbours
// less W, y the sample less W; each period's sums in float32, x and y
// rounded to float, each product added in turn, then added to the double
// sums before the solve; only the lower triangle, which the solve reads);
// every period (32 samples of the fit in generation 2, 64 in generation 3)
// it solves (A + r I) c = b by Cholesky (r a thousandth of A's mean
// diagonal: a flat region's singular A still solves) and scales A and b by
// the decay (0.95; 0.95^2 per 64), so the fit follows its last ~640
// samples. Solving half as often costs 0.05 % and saves a sixth of the
// time. Until its first solve a fit predicts W.
//
// Every decoder must compute the same bits: the sums, the solve and the
// prediction are IEEE doubles in a fixed order, without fused multiply-add
// (-ffp-contract=off on the files that include this, CMakeLists.txt),
// rounded to the nearest integer (ties to even) under the default rounding
// mode. Nothing here enters the FTZ/DAZ flags' domain: the sums are of
// integer products, and what the decay brings below 2^-600 (a fit that
// sees only flat background for millions of samples) is set to 0 before it
// could become subnormal; a fit that fails (a pivot <= 0, NaN) keeps its
// previous weights, weights below 2^-600 are 0.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

namespace vdbdag::coding::detail {

inline constexpr int kLsMaxTaps = 24;  // generation 3's; generation 2 has 19
inline constexpr int kLsStride = 24;   // a row of the sums: kLsMaxTaps, whole AVX2 vectors of floats
inline constexpr double kLsTiny = 0x1p-600;  // below this a sum or weight is 0
inline constexpr double kLsRidge = 1e-3;   // of the mean diagonal

// A generation's fit: its neighbours (the near seven besides W, then the
// first taps - 7 far ones), the samples between solves and what the sums
// keep at each solve.
struct LsShape {
    int taps;
    int period;
    double decay;
};
inline constexpr LsShape kLsGeneration2{19, 32, 0.95};
inline constexpr LsShape kLsGeneration3{24, 64, 0.95 * 0.95};

// The neighbours beyond the near eight (SamplePredictor.h's Neighbourhood
// holds W, N, NW, NE, P, PW, PN, PNW): generation 2 uses the first 12,
// generation 3 all 17; the walks fill every one (a missing neighbour: its
// nearest coded substitute).
enum FarNeighbour { kWW, kNN, kPP, kPE, kPS, kPNE, kPSW, kPSE, kNWW, kNNE, kNNW, kNEE, kWWW, kWWWW, kNWWW, kNEEE, kNNN, kFarNeighbours };
static_assert(7 + kFarNeighbours == kLsMaxTaps);

// pa[i kLsStride + j] += x[i] x[j] for j <= i (and on to the end of j's
// 8-float vector; x zero past `taps`) and pb[i] += x[i] y, for i < taps,
// each a float product added in turn (LeastSquaresKernels.cpp).
void addProducts(float* pa, float* pb, const float* x, float y, int taps);
// Solves (A + r I) w = b (A's lower triangle, rows of kLsStride, `taps`
// of them; r kLsRidge times A's mean diagonal, plus 1e-6) by Cholesky and
// stores w in c, unless a pivot is not positive or a weight is not finite
// (c then keeps its weights); weights below kLsTiny are 0
// (LeastSquaresKernels.cpp).
void solveFit(const double* a, const double* b, double* c, int taps);

struct LeastSquaresFit {
    LsShape shape = kLsGeneration2;
    std::array<double, kLsMaxTaps * kLsStride> a{};  // sum x x^T, the lower triangle (what the solve reads)
    std::array<double, kLsMaxTaps> b{};              // sum x y
    std::array<double, kLsMaxTaps> c{};              // the weights
    int count = 0;                                   // samples since the last solve
    // This period's sums, in float: 4 or 8 products a step (SSE2, AVX2:
    // LeastSquaresKernels.cpp), 1.3x faster overall than doubles; exact for
    // samples of up to 9 bits (|x| < 724: 32 x^2 < 2^24), and rounded alike
    // everywhere beyond. Rows of kLsStride; past the triangle unused.
    alignas(32) std::array<float, kLsMaxTaps * kLsStride> pa{};
    alignas(32) std::array<float, kLsMaxTaps> pb{};

    // The prediction for the neighbours `x` (relative to `ref`), unrounded.
    double predict(const std::array<double, kLsMaxTaps>& x, double ref) const {
        double q = ref;
        for (int k = 0; k < shape.taps; ++k) q += c[size_t(k)] * x[size_t(k)];
        return q;
    }

    void learn(const std::array<double, kLsMaxTaps>& x, double y) {
        alignas(32) float xf[kLsStride] = {};
        for (int i = 0; i < shape.taps; ++i) xf[i] = float(x[size_t(i)]);
        addProducts(pa.data(), pb.data(), xf, float(y), shape.taps);
        if (++count < shape.period) return;
        count = 0;
        for (size_t i = 0; i < size_t(shape.taps); ++i) {
            for (size_t j = 0; j <= i; ++j) a[i * kLsStride + j] += double(pa[i * kLsStride + j]);
            b[i] += double(pb[i]);
        }
        pa.fill(0.0f);
        pb.fill(0.0f);
        solveFit(a.data(), b.data(), c.data(), shape.taps);
        const auto decay = [&](double& v) { v = std::abs(v) < kLsTiny ? 0.0 : v * shape.decay; };
        for (size_t i = 0; i < size_t(shape.taps); ++i) {  // the triangle the sums fill; the rest stays 0
            for (size_t j = 0; j <= i; ++j) decay(a[i * kLsStride + j]);
            decay(b[i]);
        }
    }
};

} // namespace vdbdag::coding::detail
