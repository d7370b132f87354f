// See MpiTeam.h.
#include "distributed/MpiTeam.h"

#include <mpi.h>

#include <algorithm>

namespace vdbdag::distributed {
namespace {

constexpr uint64_t kChunk = uint64_t(1) << 30;

void sendAll(const uint8_t* data, uint64_t size, int to) {
    for (uint64_t done = 0; done < size; done += kChunk)
        MPI_Send(data + done, int(std::min(kChunk, size - done)), MPI_BYTE, to, 0, MPI_COMM_WORLD);
}

void receiveAll(uint8_t* data, uint64_t size, int from) {
    for (uint64_t done = 0; done < size; done += kChunk)
        MPI_Recv(data + done, int(std::min(kChunk, size - done)), MPI_BYTE, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

} // namespace

MpiTeam::MpiTeam() {
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    rank_ = unsigned(rank);
    size_ = unsigned(size);
}

std::vector<std::vector<uint8_t>> MpiTeam::gather(const std::vector<uint8_t>& mine) {
    uint64_t mySize = mine.size();
    std::vector<uint64_t> sizes(size_);
    MPI_Gather(&mySize, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    if (rank_ != 0) {
        sendAll(mine.data(), mySize, 0);
        return {};
    }
    std::vector<std::vector<uint8_t>> all(size_);
    all[0] = mine;
    for (unsigned r = 1; r < size_; ++r) {
        all[r].resize(sizes[r]);
        receiveAll(all[r].data(), sizes[r], int(r));
    }
    return all;
}

void MpiTeam::gatherEach(std::vector<uint8_t> mine, const std::function<void(std::vector<uint8_t>&&)>& take) {
    uint64_t mySize = mine.size();
    std::vector<uint64_t> sizes(size_);
    MPI_Gather(&mySize, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    if (rank_ != 0) {
        sendAll(mine.data(), mySize, 0);
        return;
    }
    take(std::move(mine));
    for (unsigned r = 1; r < size_; ++r) {
        std::vector<uint8_t> bytes(sizes[r]);
        receiveAll(bytes.data(), sizes[r], int(r));
        take(std::move(bytes));
    }
}

std::vector<uint8_t> MpiTeam::broadcast(const std::vector<uint8_t>& bytes) {
    uint64_t size = bytes.size();
    MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    std::vector<uint8_t> out = rank_ == 0 ? bytes : std::vector<uint8_t>(size);
    for (uint64_t done = 0; done < size; done += kChunk)
        MPI_Bcast(out.data() + done, int(std::min(kChunk, size - done)), MPI_BYTE, 0, MPI_COMM_WORLD);
    return out;
}

} // namespace vdbdag::distributed
