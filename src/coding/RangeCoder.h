// An adaptive binary range coder (the carry-less LZMA construction: 32-bit
// range, 64-bit low with a cached byte for the carry) and the adaptive bit
// model the value coders build on.
//
// A bit is coded under a model that holds the probability of a 0 as two
// 16-bit estimates adapting at different speeds (1/32 and 1/128 per bit),
// averaged: the fast one follows local changes, the slow one keeps the
// long-run rate. Both stay inside [15, 65521], so the coded interval never
// collapses (a warmed-up model, BitModel::warmUp, takes larger steps over
// its first 31 bits only, from 1/2, and so ends them well inside).
//
// The decoder reads past the end of its bytes as zeros and counts how far
// it went: a corrupt or truncated stream decodes to garbage in bounded time,
// never reads out of bounds, and `overrun()` tells the caller to refuse it.
#pragma once
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

namespace vdbdag::coding {

struct BitModel {
    uint16_t fast = 32768, slow = 32768;  // P(bit == 0) in 1/65536
    // Updates seen while warming up (warmUp(): from 0 to 31); 255, a model
    // that adapts at 1/32 and 1/128 from the start.
    uint8_t seen = 255;
    uint32_t p0() const { return (uint32_t(fast) + uint32_t(slow)) >> 1; }
    // A model that learns its first bits fast: its n-th update (from 0)
    // moves both estimates by 2^-(1 + bit_width(n + 1)) (1/4, 1/8, 1/8,
    // 1/16 x4, 1/32 x8 (the fast one's own rate), 1/64 x16 for the slow
    // one) until both adapt at their own rates (after 31). What many sparse
    // contexts need: a fresh model at 1/2 pays for its first dozens of
    // bits at 1/32 (integer model generation 4, SamplePredictor.h).
    void warmUp() { seen = 0; }
    void update(unsigned bit) {
        unsigned fs = 5, ss = 7;
        if (seen < 31) {
            const unsigned w = 1 + unsigned(std::bit_width(unsigned(seen) + 1u));
            fs = w < 5 ? w : 5, ss = w < 7 ? w : 7;
            ++seen;
        }
        if (bit) {
            fast = uint16_t(fast - (fast >> fs));
            slow = uint16_t(slow - (slow >> ss));
        } else {
            fast = uint16_t(fast + ((65536u - fast) >> fs));
            slow = uint16_t(slow + ((65536u - slow) >> ss));
        }
    }
};

class RangeEncoder {
public:
    explicit RangeEncoder(std::vector<uint8_t>& out) : out_(out) {}
    void encode(BitModel& m, unsigned bit) {
        const uint32_t bound = (range_ >> 16) * m.p0();
        if (bit) {
            low_ += bound;
            range_ -= bound;
        } else {
            range_ = bound;
        }
        m.update(bit);
        while (range_ < (1u << 24)) {
            range_ <<= 8;
            shiftLow();
        }
    }
    // Bits at probability 1/2 (no model), most significant first.
    void encodeDirect(uint32_t value, unsigned bits) {
        for (unsigned i = bits; i-- > 0;) {
            range_ >>= 1;
            if ((value >> i) & 1u) low_ += range_;
            while (range_ < (1u << 24)) {
                range_ <<= 8;
                shiftLow();
            }
        }
    }
    // Up to 32 bits at probability 1/2, at most 8 per step (one multiply
    // instead of a step per bit); a stream of its own, not encodeDirect's.
    void encodeBits(uint32_t value, unsigned bits) {
        while (bits > 0) {
            const unsigned k = bits < 8 ? bits : 8;
            bits -= k;
            range_ >>= k;
            low_ += uint64_t((value >> bits) & ((1u << k) - 1)) * range_;
            while (range_ < (1u << 24)) {
                range_ <<= 8;
                shiftLow();
            }
        }
    }
    void finish() {
        for (int i = 0; i < 5; ++i) shiftLow();
    }

private:
    void shiftLow() {
        if (uint32_t(low_) < 0xFF000000u || (low_ >> 32) != 0) {
            const uint8_t carry = uint8_t(low_ >> 32);
            uint8_t byte = cache_;
            do {
                out_.push_back(uint8_t(byte + carry));
                byte = 0xFF;
            } while (--pending_ != 0);
            cache_ = uint8_t(low_ >> 24);
        }
        ++pending_;
        low_ = (low_ & 0x00FFFFFFu) << 8;
    }
    std::vector<uint8_t>& out_;
    uint64_t low_ = 0;
    uint32_t range_ = 0xFFFFFFFFu;
    uint8_t cache_ = 0;
    uint64_t pending_ = 1;
};

class RangeDecoder {
public:
    explicit RangeDecoder(std::span<const uint8_t> in) : in_(in) {
        for (int i = 0; i < 5; ++i) code_ = (code_ << 8) | next();
    }
    unsigned decode(BitModel& m) {
        const uint32_t bound = (range_ >> 16) * m.p0();
        unsigned bit;
        if (code_ < bound) {
            range_ = bound;
            bit = 0;
        } else {
            code_ -= bound;
            range_ -= bound;
            bit = 1;
        }
        m.update(bit);
        while (range_ < (1u << 24)) {
            range_ <<= 8;
            code_ = (code_ << 8) | next();
        }
        return bit;
    }
    uint32_t decodeDirect(unsigned bits) {
        uint32_t value = 0;
        for (unsigned i = 0; i < bits; ++i) {
            range_ >>= 1;
            const unsigned bit = code_ >= range_ ? 1u : 0u;
            if (bit) code_ -= range_;
            value = (value << 1) | bit;
            while (range_ < (1u << 24)) {
                range_ <<= 8;
                code_ = (code_ << 8) | next();
            }
        }
        return value;
    }
    // Inverse of RangeEncoder::encodeBits. A corrupt stream decodes to
    // some value of `bits` bits.
    uint32_t decodeBits(unsigned bits) {
        uint32_t value = 0;
        while (bits > 0) {
            const unsigned k = bits < 8 ? bits : 8;
            bits -= k;
            range_ >>= k;
            uint32_t v = code_ / range_;
            if (v >> k) v = (1u << k) - 1;
            code_ -= v * range_;
            value = (value << k) | v;
            while (range_ < (1u << 24)) {
                range_ <<= 8;
                code_ = (code_ << 8) | next();
            }
        }
        return value;
    }
    // Bytes asked for beyond the end (the encoder's flush makes up to 4 of
    // them legitimate).
    uint64_t overrun() const { return past_; }
    size_t consumed() const { return at_; }
    // How a finished stream ends wrongly, or null when it ends as the
    // encoder's flush leaves it (at most 4 bytes never needed, at most 4
    // read past the end): "early" or "before the stream does".
    const char* endFault() const { return past_ > 4 ? "early" : at_ + 4 < in_.size() ? "before the stream does" : nullptr; }

private:
    uint32_t next() {
        if (at_ < in_.size()) return in_[at_++];
        ++past_;
        return 0;
    }
    std::span<const uint8_t> in_;
    size_t at_ = 0;
    uint64_t past_ = 0;
    uint32_t code_ = 0, range_ = 0xFFFFFFFFu;
};

} // namespace vdbdag::coding
