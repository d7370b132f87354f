// Generation 2 of the integer value coders' prediction (SamplePredictor.h):
// a linear prediction from 19 causal neighbours whose weights are the least-
// squares fit of the samples already coded, one fit per activity context.
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
// The fit: each context sums x x^T and x y of its samples (x the 19
// neighbours less W, y the sample less W); every 32 samples it solves
// (A + r I) c = b by Cholesky (r a thousandth of A's mean diagonal: a flat
// region's singular A still solves) and scales A and b by 0.95, so the fit
// follows the last ~640 samples of the context (against 64 and 0.9: 0.1-
// 0.3 % smaller, 20 % slower). Until its first solve a context predicts W.
//
// Every decoder must compute the same bits: the sums, the solve and the
// prediction are IEEE doubles in a fixed order, without fused multiply-add
// (-ffp-contract=off on the files that include this, CMakeLists.txt),
// rounded to the nearest integer (ties to even) under the default rounding
// mode. Nothing here enters the FTZ/DAZ flags' domain: the sums are of
// integer products, and what the decay brings below 2^-600 (a context that
// sees only flat background for millions of samples) is set to 0 before it
// could become subnormal; a fit that fails (a pivot <= 0, NaN) keeps its
// previous weights, weights below 2^-600 are 0.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

namespace vdbdag::coding::detail {

inline constexpr int kLsTaps = 19;  // the near seven besides W, and the far twelve
inline constexpr int kLsPeriod = 32;       // samples of a context between solves
inline constexpr double kLsDecay = 0.95;   // what the sums keep at each solve
inline constexpr double kLsTiny = 0x1p-600;  // below this a sum or weight is 0
inline constexpr double kLsRidge = 1e-3;   // of the mean diagonal

// The 12 neighbours beyond the near eight (SamplePredictor.h's Neighbourhood
// holds W, N, NW, NE, P, PW, PN, PNW); the walks fill every one (a missing
// neighbour: its nearest coded substitute).
enum FarNeighbour { kWW, kNN, kPP, kPE, kPS, kPNE, kPSW, kPSE, kNWW, kNNE, kNNW, kNEE, kFarNeighbours };

struct LeastSquaresFit {
    std::array<double, kLsTaps * kLsTaps> a{};  // lower triangle of sum x x^T
    std::array<double, kLsTaps> b{};            // sum x y
    std::array<double, kLsTaps> c{};            // the weights
    int count = 0;                              // samples since the last solve

    // The prediction for the neighbours `x` (relative to `ref`), unrounded.
    double predict(const std::array<double, kLsTaps>& x, double ref) const {
        double q = ref;
        for (int k = 0; k < kLsTaps; ++k) q += c[size_t(k)] * x[size_t(k)];
        return q;
    }

    void learn(const std::array<double, kLsTaps>& x, double y) {
        for (int i = 0; i < kLsTaps; ++i) {
            for (int j = 0; j <= i; ++j) a[size_t(i * kLsTaps + j)] += x[size_t(i)] * x[size_t(j)];
            b[size_t(i)] += x[size_t(i)] * y;
        }
        if (++count < kLsPeriod) return;
        count = 0;
        solve();
        for (double& v : a) v = std::abs(v) < kLsTiny ? 0.0 : v * kLsDecay;
        for (double& v : b) v = std::abs(v) < kLsTiny ? 0.0 : v * kLsDecay;
    }

private:
    void solve() {
        double trace = 0;
        for (int i = 0; i < kLsTaps; ++i) trace += a[size_t(i * kLsTaps + i)];
        const double ridge = kLsRidge * trace / kLsTaps + 1e-6;
        std::array<double, kLsTaps * kLsTaps> l{};  // A + r I = L L^T
        std::array<double, kLsTaps> inv{};          // 1 / L's diagonal
        for (int i = 0; i < kLsTaps; ++i)
            for (int j = 0; j <= i; ++j) {
                double s = a[size_t(i * kLsTaps + j)] + (i == j ? ridge : 0.0);
                for (int k = 0; k < j; ++k) s -= l[size_t(i * kLsTaps + k)] * l[size_t(j * kLsTaps + k)];
                if (i == j) {
                    if (!(s > 0)) return;  // keep the previous weights
                    l[size_t(i * kLsTaps + i)] = std::sqrt(s);
                    inv[size_t(i)] = 1.0 / l[size_t(i * kLsTaps + i)];
                } else {
                    l[size_t(i * kLsTaps + j)] = s * inv[size_t(j)];
                }
            }
        std::array<double, kLsTaps> z{};
        for (int i = 0; i < kLsTaps; ++i) {
            double s = b[size_t(i)];
            for (int k = 0; k < i; ++k) s -= l[size_t(i * kLsTaps + k)] * z[size_t(k)];
            z[size_t(i)] = s * inv[size_t(i)];
        }
        std::array<double, kLsTaps> w{};
        for (int i = kLsTaps - 1; i >= 0; --i) {
            double s = z[size_t(i)];
            for (int k = i + 1; k < kLsTaps; ++k) s -= l[size_t(k * kLsTaps + i)] * w[size_t(k)];
            w[size_t(i)] = s * inv[size_t(i)];
        }
        for (double& v : w) {
            if (!std::isfinite(v)) return;
            if (std::abs(v) < kLsTiny) v = 0;
        }
        c = w;
    }
};

} // namespace vdbdag::coding::detail
