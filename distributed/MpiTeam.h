// The processes of an `mpirun` as a CubeTeam (src/pipeline/CubeTeam.h): the
// only code of vdbdag that sees MPI. Messages of any size are sent in
// chunks of at most 1 GiB (MPI counts are int).
#pragma once
#include "src/pipeline/CubeTeam.h"

namespace vdbdag::distributed {

class MpiTeam final : public pipeline::CubeTeam {
public:
    MpiTeam();  // MPI must be initialised
    unsigned rank() const override { return rank_; }
    unsigned size() const override { return size_; }
    std::vector<std::vector<uint8_t>> gather(const std::vector<uint8_t>& mine) override;
    void gatherEach(std::vector<uint8_t> mine, const std::function<void(std::vector<uint8_t>&&)>& take) override;
    std::vector<uint8_t> broadcast(const std::vector<uint8_t>& bytes) override;

private:
    unsigned rank_ = 0, size_ = 1;
};

} // namespace vdbdag::distributed
