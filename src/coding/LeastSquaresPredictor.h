// Generation 2 of the integer value coders' prediction (SamplePredictor.h):
// a linear prediction from 19 causal neighbours whose weights are the least-
// squares fit of the samples already coded, one fit per four activity
// contexts (SamplePredictor.h).
//
// Why: the blend of six fixed predictors (generations 0 and 1) cannot learn
// a scan's own correlations: an MR's smooth tissue wants most of its weight
// on the previous slice, a CT's streaks on the row above, a tooth's noise an
// average of many. A fit over the last few thousand samples of the same
// activity finds those weights; on the shared scans it codes 3-7 % smaller
// than the blend (docs/int_coder.md), at about twice the time.
//
// The neighbours, relative to W (so a constant offset costs nothing):
//      this slice:  NNW NN NNE         slice below:  PNW PN PNE     two below: PP
//                   NWW NW N NE NEE                  PW  P  PE
//                   WW  W  *                         PSW PS PSE
// The slice below is wholly coded in raster order (IntVolumeCoder); the
// placed walk of a DAG's bricks has all but those in bricks not yet visited,
// and substitutes the nearest coded one (PlacedWalk.h).
//
// The fit: each fit sums x x^T and x y of its samples (x the 19
// neighbours less W, y the sample less W; each period's sums in float32,
// x and y rounded to float, each product added in turn, then added to the
// double sums before the solve); every 32 of its samples it solves
// (A + r I) c = b by Cholesky (r a thousandth of A's mean diagonal: a flat
// region's singular A still solves) and scales A and b by 0.95, so the fit
// follows its last ~640 samples (against 64 and 0.9: 0.1-0.3 % smaller, 20 %
// slower). Until its first solve a fit predicts W.
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

inline constexpr int kLsTaps = 19;  // the near seven besides W, and the far twelve
inline constexpr int kLsStride = 24;  // a row of the float sums: kLsTaps, padded to whole AVX2 vectors
inline constexpr int kLsPeriod = 32;       // samples of a fit between solves
inline constexpr double kLsDecay = 0.95;   // what the sums keep at each solve
inline constexpr double kLsTiny = 0x1p-600;  // below this a sum or weight is 0
inline constexpr double kLsRidge = 1e-3;   // of the mean diagonal

// The 12 neighbours beyond the near eight (SamplePredictor.h's Neighbourhood
// holds W, N, NW, NE, P, PW, PN, PNW); the walks fill every one (a missing
// neighbour: its nearest coded substitute).
enum FarNeighbour { kWW, kNN, kPP, kPE, kPS, kPNE, kPSW, kPSE, kNWW, kNNE, kNNW, kNEE, kFarNeighbours };

// pa[i kLsStride + j] += x[i] x[j] (j < kLsStride, x zero past kLsTaps) and
// pb[i] += x[i] y, for i < kLsTaps, each a float product added in turn
// (LeastSquaresKernels.cpp).
void addProducts(float* pa, float* pb, const float* x, float y);
// Solves (A + r I) w = b (A kLsTaps^2, row-major; r kLsRidge times A's mean
// diagonal, plus 1e-6) by Cholesky and stores w in c, unless a pivot is not
// positive or a weight is not finite (c then keeps its weights); weights
// below kLsTiny are 0 (LeastSquaresKernels.cpp).
void solveFit(const double* a, const double* b, double* c);

struct LeastSquaresFit {
    std::array<double, kLsTaps * kLsTaps> a{};  // sum x x^T (the solve reads the lower triangle)
    std::array<double, kLsTaps> b{};            // sum x y
    std::array<double, kLsTaps> c{};            // the weights
    int count = 0;                              // samples since the last solve
    // This period's sums, in float: 4 or 8 products a step (SSE2, AVX2:
    // LeastSquaresKernels.cpp), 1.3x faster overall than doubles; exact for
    // samples of up to 9 bits (|x| < 724: 32 x^2 < 2^24), and rounded alike
    // everywhere beyond. Rows of kLsStride, the padding's sums 0 and unused.
    alignas(32) std::array<float, kLsTaps * kLsStride> pa{};
    alignas(32) std::array<float, kLsTaps> pb{};

    // The prediction for the neighbours `x` (relative to `ref`), unrounded.
    double predict(const std::array<double, kLsTaps>& x, double ref) const {
        double q = ref;
        for (int k = 0; k < kLsTaps; ++k) q += c[size_t(k)] * x[size_t(k)];
        return q;
    }

    void learn(const std::array<double, kLsTaps>& x, double y) {
        alignas(32) float xf[kLsStride] = {};
        for (int i = 0; i < kLsTaps; ++i) xf[i] = float(x[size_t(i)]);
        addProducts(pa.data(), pb.data(), xf, float(y));
        if (++count < kLsPeriod) return;
        count = 0;
        for (size_t i = 0; i < size_t(kLsTaps); ++i)
            for (size_t j = 0; j < size_t(kLsTaps); ++j) a[i * kLsTaps + j] += double(pa[i * kLsStride + j]);
        pa.fill(0.0f);
        for (size_t i = 0; i < b.size(); ++i) b[i] += double(pb[i]), pb[i] = 0;
        solve();
        for (double& v : a) v = std::abs(v) < kLsTiny ? 0.0 : v * kLsDecay;
        for (double& v : b) v = std::abs(v) < kLsTiny ? 0.0 : v * kLsDecay;
    }

private:
    // (A + r I) c = b, c kept where the solve fails (solveFit).
    void solve() { solveFit(a.data(), b.data(), c.data()); }
};

} // namespace vdbdag::coding::detail
