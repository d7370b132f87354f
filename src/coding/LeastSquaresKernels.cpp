// The hot loops of the least-squares fits (LeastSquaresPredictor.h): each
// sample's products added to its fit's float sums, and the solve. Compiled twice on x86-64
// (target_clones: AVX2 and the baseline, chosen once at load time by the
// CPU), with the same bits either way: a vector lane does what the scalar
// code does to one element (a product added to a sum, in the same order),
// the sums over k stay scalar and in order, and neither clone may fuse a
// multiply and an add (-ffp-contract=off on this file; AVX2 alone has no
// FMA). Against the baseline alone: 4-5 % off a dense CT's encode.
#include "src/coding/LeastSquaresPredictor.h"

#include <array>
#include <cmath>
#include <cstddef>

namespace vdbdag::coding::detail {

#if defined(__x86_64__) && (!defined(__clang__) || __clang_major__ >= 14)
__attribute__((target_clones("avx2", "default")))
#endif
void addProducts(float* pa, float* pb, const float* x, float y, int taps) {
    for (int i = 0; i < taps; ++i) {
        const float xi = x[i];
        float* row = pa + i * kLsStride;
        const int end = (i / 8 + 1) * 8;  // the lower triangle, to whole vectors (at most kLsStride)
        for (int j = 0; j < end; ++j) row[j] += xi * x[j];
        pb[i] += xi * y;
    }
}

// A + r I = L L^T by Cholesky, then L z = b and L^T w = z. Each element of L
// and z is a_ij (b_i) less its products in increasing k, then scaled: written
// column by column ("right-looking", L's columns contiguous: col[k][i] =
// L(i, k)), so the compiler vectorises the updates without reordering any
// element's sums; the back substitution's sums stay in order.
#if defined(__x86_64__) && (!defined(__clang__) || __clang_major__ >= 14)
__attribute__((target_clones("avx2", "default")))
#endif
void solveFit(const double* a, const double* b, double* c, int taps) {
    const size_t T = size_t(taps);
    double trace = 0;
    for (size_t i = 0; i < T; ++i) trace += a[i * kLsStride + i];
    const double ridge = kLsRidge * trace / double(taps) + 1e-6;
    std::array<double, kLsMaxTaps * kLsMaxTaps> col{};
    std::array<double, kLsMaxTaps> inv{};  // 1 / L's diagonal
    for (size_t k = 0; k < T; ++k)
        for (size_t i = k; i < T; ++i) col[k * T + i] = a[i * kLsStride + k] + (i == k ? ridge : 0.0);
    std::array<double, kLsMaxTaps> z;
    for (size_t i = 0; i < T; ++i) z[i] = b[i];
    for (size_t j = 0; j < T; ++j) {
        double* cj = &col[j * T];
        if (!(cj[j] > 0)) return;  // keep the previous weights
        cj[j] = std::sqrt(cj[j]);
        inv[j] = 1.0 / cj[j];
        for (size_t i = j + 1; i < T; ++i) cj[i] *= inv[j];
        for (size_t k = j + 1; k < T; ++k) {
            double* ck = &col[k * T];
            const double f = cj[k];
            for (size_t i = k; i < T; ++i) ck[i] -= cj[i] * f;
        }
        z[j] *= inv[j];
        for (size_t i = j + 1; i < T; ++i) z[i] -= cj[i] * z[j];
    }
    std::array<double, kLsMaxTaps> w{};
    for (size_t i = T; i-- > 0;) {
        double s = z[i];
        for (size_t k = i + 1; k < T; ++k) s -= col[i * T + k] * w[k];
        w[i] = s * inv[i];
    }
    for (size_t i = 0; i < T; ++i) {
        double& v = w[i];
        if (!std::isfinite(v)) return;
        if (std::abs(v) < kLsTiny) v = 0;
    }
    for (size_t i = 0; i < T; ++i) c[i] = w[i];
}

} // namespace vdbdag::coding::detail
