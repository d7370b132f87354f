// See ReducedDagBytes.h. Layout: origin (3 x i64), log2Size (u32), root
// (u32), the svo counts, the bricks, then per inner level its nodes; each
// array as a u64 count followed by its elements.
#include "src/dag/ReducedDagBytes.h"

#include <cstring>
#include <string>

#include "src/dag/LevelBuilder.h"
#include "src/util/Error.h"

namespace vdbdag::dag {
namespace {

template <typename T>
void put(std::vector<uint8_t>& out, const T& value) {
    const auto* p = reinterpret_cast<const uint8_t*>(&value);
    out.insert(out.end(), p, p + sizeof(T));
}
template <typename T>
void putArray(std::vector<uint8_t>& out, const std::vector<T>& values) {
    put<uint64_t>(out, values.size());
    const auto* p = reinterpret_cast<const uint8_t*>(values.data());
    out.insert(out.end(), p, p + values.size() * sizeof(T));
}
template <typename T>
T get(const std::vector<uint8_t>& in, size_t& pos) {
    if (in.size() - pos < sizeof(T) || pos > in.size()) throw Error("internal error: a sub-DAG message is cut short");
    T value;
    std::memcpy(&value, in.data() + pos, sizeof(T));
    pos += sizeof(T);
    return value;
}
template <typename T>
std::vector<T> getArray(const std::vector<uint8_t>& in, size_t& pos) {
    const uint64_t n = get<uint64_t>(in, pos);
    if (n > (in.size() - pos) / sizeof(T)) throw Error("internal error: a sub-DAG message is cut short");
    std::vector<T> values(n);
    std::memcpy(values.data(), in.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
    return values;
}

} // namespace

void appendReducedDag(const ReducedDag& dag, std::vector<uint8_t>& out) {
    for (int64_t o : dag.origin) put(out, o);
    put<uint32_t>(out, dag.log2Size);
    put<uint32_t>(out, dag.root);
    putArray(out, dag.svoNodeCount);
    putArray(out, dag.bricks);
    put<uint64_t>(out, dag.inner.size());
    for (const InnerLevel& level : dag.inner) putArray(out, level.nodes);
}

ReducedDag readReducedDag(const std::vector<uint8_t>& bytes, size_t& pos) {
    ReducedDag dag;
    for (int64_t& o : dag.origin) o = get<int64_t>(bytes, pos);
    dag.log2Size = get<uint32_t>(bytes, pos);
    dag.root = get<uint32_t>(bytes, pos);
    dag.svoNodeCount = getArray<uint64_t>(bytes, pos);
    dag.bricks = getArray<uint64_t>(bytes, pos);
    const uint64_t levels = get<uint64_t>(bytes, pos);
    if (levels > 64 || (dag.log2Size && levels != dag.log2Size - 2)) throw Error("internal error: a sub-DAG message has a bad level count");
    dag.inner.resize(levels);
    for (InnerLevel& level : dag.inner) level.nodes = getArray<InnerNode>(bytes, pos);
    if (dag.root) countReferences(dag);
    return dag;
}

} // namespace vdbdag::dag
