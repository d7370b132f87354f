// A ReducedDag as bytes, to move sub-DAGs and merged DAGs between the
// processes of a distributed encode (pipeline/CubeTeam.h). Reference counts
// are not sent: the receiver recounts them (countReferences). Native byte
// order: the processes of one encode run the same binary.
#pragma once
#include <cstdint>
#include <vector>

#include "src/dag/ReducedDag.h"

namespace vdbdag::dag {

void appendReducedDag(const ReducedDag& dag, std::vector<uint8_t>& out);
// Reads one DAG at `pos`, advancing it; throws vdbdag::Error on short or
// inconsistent bytes.
ReducedDag readReducedDag(const std::vector<uint8_t>& bytes, size_t& pos);

} // namespace vdbdag::dag
