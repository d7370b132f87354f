// The 8 reflections about a node's centre planes (SSVDAG paper §3, §4.1).
// A reflection is a 3-bit mask m: bit 0 mirrors x, bit 1 mirrors y, bit 2 z.
// Reflections commute and are involutions, so the 8 of them form the group
// Z2^3 under XOR; a set of reflections is an 8-bit mask (bit g = reflection g).
//
//  - Inner node: child slot i = x | y<<1 | z<<2 (x,y,z in 0..1); reflecting
//    the node by m moves child i to slot i^m and XORs m into its tag.
//  - 4^3 brick: bit x + 4y + 16z; reflecting by m maps x -> 3-x (if m&1), ...
//    which is a fixed bit permutation (reflectBrick).
#pragma once
#include <array>
#include <cstdint>

#include <vdbdag/dag_access.h>

namespace vdbdag::dag {

// Reflects a 4^3 brick mask by m.
constexpr uint64_t reflectBrick(uint64_t mask, unsigned m) { return access::dagReflectBrick(mask, m); }

// A set of reflections that leaves a node unchanged is a subgroup G; a child
// tag t is then only defined modulo G. canonicalTag(t, G) = min{t ^ g : g in G}
// picks one representative of the coset so equal geometry compares equal.
struct CanonicalTagTable {
    std::array<std::array<uint8_t, 8>, 256> table{};
    constexpr CanonicalTagTable() {
        for (unsigned set = 0; set < 256; ++set)
            for (unsigned t = 0; t < 8; ++t) {
                unsigned best = t;
                for (unsigned g = 0; g < 8; ++g)
                    if ((set >> g) & 1u) best = (t ^ g) < best ? (t ^ g) : best;
                table[set][t] = uint8_t(best);
            }
    }
};
inline constexpr CanonicalTagTable kCanonicalTag{};
inline uint8_t canonicalTag(unsigned tag, uint8_t invarianceSet) { return kCanonicalTag.table[invarianceSet][tag]; }

// Canonical form of a brick: the largest of its 8 reflections (paper §4.1:
// "the one that attracts most of the empty space to the origin").
struct BrickCanonicalForm {
    uint64_t mask;         // canonical representative
    uint8_t reflection;    // original == reflectBrick(mask, reflection)
    uint8_t invariance;    // set of reflections g with reflectBrick(original, g) == original
};

inline BrickCanonicalForm canonicalBrick(uint64_t original, bool useSymmetry) {
    if (!useSymmetry) return {original, 0, 1};
    uint64_t reflected[8];
    for (unsigned m = 0; m < 8; ++m) reflected[m] = reflectBrick(original, m);
    BrickCanonicalForm form{original, 0, 0};
    for (unsigned m = 0; m < 8; ++m) {
        if (reflected[m] > form.mask) { form.mask = reflected[m]; form.reflection = uint8_t(m); }
        if (reflected[m] == original) form.invariance |= uint8_t(1u << m);
    }
    return form;
}

} // namespace vdbdag::dag
