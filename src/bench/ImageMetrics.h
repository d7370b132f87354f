// Image error metrics for `vdbdag bench`: PSNR and SSIM of a render against
// the lossless full-resolution render (Benthin et al.: report the error a
// lossy setting costs in the image, not only in the values). Both work on
// display values (sRGB-encoded, clamped to [0, 1]) as a viewer sees them.
#pragma once
#include "src/trace/Image.h"

namespace vdbdag::bench {

// Peak signal-to-noise ratio over R, G, B in dB; +inf for identical images.
double psnr(const trace::Image& reference, const trace::Image& test);
// Mean structural similarity (Wang et al. 2004) of the luma, 8x8 windows
// with stride 4, C1 = (0.01)^2, C2 = (0.03)^2; 1 for identical images.
double ssim(const trace::Image& reference, const trace::Image& test);

} // namespace vdbdag::bench
