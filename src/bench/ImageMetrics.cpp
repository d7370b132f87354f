// PSNR and SSIM; see ImageMetrics.h.
#include "src/bench/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "src/util/Error.h"

namespace vdbdag::bench {
namespace {

double display(float linear) {
    const double c = std::clamp(std::isfinite(linear) ? double(linear) : 0.0, 0.0, 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
}

void checkSameSize(const trace::Image& a, const trace::Image& b) {
    if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
        throw Error("image metrics: the images differ in size");
}

std::vector<double> luma(const trace::Image& image) {
    std::vector<double> y(size_t(image.width) * size_t(image.height));
    for (size_t i = 0; i < y.size(); ++i)
        y[i] = 0.2126 * display(image.rgb[3 * i]) + 0.7152 * display(image.rgb[3 * i + 1]) + 0.0722 * display(image.rgb[3 * i + 2]);
    return y;
}

} // namespace

double psnr(const trace::Image& reference, const trace::Image& test) {
    checkSameSize(reference, test);
    double sum = 0;
    for (size_t i = 0; i < reference.rgb.size(); ++i) {
        const double d = display(reference.rgb[i]) - display(test.rgb[i]);
        sum += d * d;
    }
    const double mse = sum / double(std::max<size_t>(1, reference.rgb.size()));
    return mse == 0 ? std::numeric_limits<double>::infinity() : 10 * std::log10(1.0 / mse);
}

double ssim(const trace::Image& reference, const trace::Image& test) {
    checkSameSize(reference, test);
    const std::vector<double> a = luma(reference), b = luma(test);
    const int w = reference.width, h = reference.height, window = std::min({8, w, h}), stride = std::max(1, window / 2);
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    double total = 0;
    size_t windows = 0;
    for (int y0 = 0; y0 + window <= h; y0 += stride)
        for (int x0 = 0; x0 + window <= w; x0 += stride) {
            double ma = 0, mb = 0;
            for (int y = y0; y < y0 + window; ++y)
                for (int x = x0; x < x0 + window; ++x) { ma += a[size_t(y) * w + x]; mb += b[size_t(y) * w + x]; }
            const double n = double(window) * window;
            ma /= n;
            mb /= n;
            double va = 0, vb = 0, cov = 0;
            for (int y = y0; y < y0 + window; ++y)
                for (int x = x0; x < x0 + window; ++x) {
                    const double da = a[size_t(y) * w + x] - ma, db = b[size_t(y) * w + x] - mb;
                    va += da * da;
                    vb += db * db;
                    cov += da * db;
                }
            va /= n - 1;
            vb /= n - 1;
            cov /= n - 1;
            total += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            ++windows;
        }
    return windows ? total / double(windows) : 1.0;
}

} // namespace vdbdag::bench
