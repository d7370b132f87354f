// The processes sharing one out-of-core encode (SSVDAG paper §4.2: reduce
// subtrees in parallel, merge bottom-up; here across processes too). Every
// process reads its own share of the input, reduces its cubes and gathers
// their values; process 0 merges, codes the values and writes the file.
// Only two collectives are needed, so the core never sees MPI: the MPI
// implementation lives in distributed/, a single process uses soloTeam().
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace vdbdag::pipeline {

class CubeTeam {
public:
    virtual ~CubeTeam() = default;
    virtual unsigned rank() const = 0;
    virtual unsigned size() const = 0;
    // Every process's bytes on process 0, in rank order; elsewhere empty.
    virtual std::vector<std::vector<uint8_t>> gather(const std::vector<uint8_t>& mine) = 0;
    // The same, handed to `take` on process 0 one process's bytes at a time,
    // in rank order, so process 0 need not hold them all at once.
    virtual void gatherEach(std::vector<uint8_t> mine, const std::function<void(std::vector<uint8_t>&&)>& take) {
        for (std::vector<uint8_t>& bytes : gather(mine)) take(std::move(bytes));
    }
    // Process 0's bytes on every process (`bytes` is ignored elsewhere).
    virtual std::vector<uint8_t> broadcast(const std::vector<uint8_t>& bytes) = 0;
    bool isRoot() const { return rank() == 0; }
};

// One process, no communication.
CubeTeam& soloTeam();

// Splits items 0..n-1 (in order) into `parts` contiguous shares of about
// equal total weight: share p is [bounds[p], bounds[p+1]).
std::vector<size_t> splitByWeight(const std::vector<uint64_t>& weights, unsigned parts);

} // namespace vdbdag::pipeline
