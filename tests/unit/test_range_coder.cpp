// The adaptive binary range coder and its bit model (src/coding/RangeCoder.h)
// against information theory: a stationary source of n bits with k ones
// cannot be coded in fewer than n H(k/n) bits, and an adaptive model that
// learns p pays about 0.5 log2 n bits more (the Krichevsky-Trofimov regret),
// plus what its fixed rate costs (a few per cent) and the coder's 5 flush
// bytes. A model made with warmUp() (integer model generation 4) must come
// close to that on a short run; a model at 1/32 from the start pays about
// 24 bits more to move from 1/2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "src/coding/RangeCoder.h"

using namespace vdbdag::coding;

namespace {

struct Coded {
    std::vector<uint8_t> bytes;
    std::vector<unsigned> bits;
    double entropyBits = 0;  // n H(k/n)
};

// n bits, a one in 32 (from a linear congruential generator), under one model.
Coded codeSkewed(int n, bool warm) {
    Coded c;
    RangeEncoder rc(c.bytes);
    BitModel m;
    if (warm) m.warmUp();
    uint32_t x = 12345;
    int ones = 0;
    for (int i = 0; i < n; ++i) {
        x = x * 1664525u + 1013904223u;
        const unsigned bit = (x >> 8) % 32 == 0;
        ones += int(bit);
        c.bits.push_back(bit);
        rc.encode(m, bit);
    }
    rc.finish();
    const double p = double(ones) / n;
    c.entropyBits = -n * (p * std::log2(p) + (1 - p) * std::log2(1 - p));
    return c;
}

} // namespace

TEST(RangeCoder, AWarmedModelCodesAShortRunNearItsEntropy) {
    for (const int n : {256, 1024}) {
        const Coded warm = codeSkewed(n, true), cold = codeSkewed(n, false);
        const double bound = warm.entropyBits * 1.05 + 0.5 * std::log2(n) + 8;  // rate's cost, KT regret, slack
        const double warmBits = double(warm.bytes.size() - 5) * 8, coldBits = double(cold.bytes.size() - 5) * 8;
        EXPECT_LE(warmBits, bound) << n << " bits, entropy " << warm.entropyBits;
        EXPECT_GT(coldBits, bound) << n << ": a model at 1/32 from the start should pay to leave 1/2";
        for (const Coded* c : {&warm, &cold}) {  // and both decode
            RangeDecoder rd(c->bytes);
            BitModel m;
            if (c == &warm) m.warmUp();
            for (size_t i = 0; i < c->bits.size(); ++i) ASSERT_EQ(rd.decode(m), c->bits[i]) << i;
            EXPECT_EQ(rd.endFault(), nullptr);
        }
    }
}

// The estimates stay inside [15, 65521] whatever the bits (the interval
// never collapses): a warmed model under a run of 10,000 equal bits.
TEST(RangeCoder, AWarmedModelStaysInsideItsBounds) {
    for (const unsigned bit : {0u, 1u}) {
        BitModel m;
        m.warmUp();
        for (int i = 0; i < 10000; ++i) {
            m.update(bit);
            ASSERT_GE(m.p0(), 15u) << i;
            ASSERT_LE(m.p0(), 65521u) << i;
        }
    }
}
