// See CubeTeam.h.
#include "src/pipeline/CubeTeam.h"

namespace vdbdag::pipeline {
namespace {

class SoloTeam final : public CubeTeam {
public:
    unsigned rank() const override { return 0; }
    unsigned size() const override { return 1; }
    std::vector<std::vector<uint8_t>> gather(const std::vector<uint8_t>& mine) override { return {mine}; }
    std::vector<uint8_t> broadcast(const std::vector<uint8_t>& bytes) override { return bytes; }
};

} // namespace

CubeTeam& soloTeam() {
    static SoloTeam team;
    return team;
}

std::vector<size_t> splitByWeight(const std::vector<uint64_t>& weights, unsigned parts) {
    if (parts == 0) parts = 1;
    long double total = 0;
    for (uint64_t w : weights) total += (long double)w;
    std::vector<size_t> bounds{0};
    long double running = 0;
    size_t i = 0;
    for (unsigned p = 1; p < parts; ++p) {
        const long double target = total * p / parts;
        while (i < weights.size() && running + (long double)weights[i] / 2 < target) running += (long double)weights[i++];
        bounds.push_back(i);
    }
    bounds.push_back(weights.size());
    return bounds;
}

} // namespace vdbdag::pipeline
