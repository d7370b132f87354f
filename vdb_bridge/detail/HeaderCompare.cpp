// See HeaderCompare.h.
#include "vdb_bridge/detail/HeaderCompare.h"

#include <set>

namespace vdbdag::bridge::detail {
namespace {

// Metadata OpenVDB's writer recomputes on every write (grid statistics and the
// compression it used): not part of what a round trip must keep.
const std::set<std::string> kWriterMetadata = {"file_bbox_min", "file_bbox_max", "file_mem_bytes", "file_voxel_count",
                                               "file_compression", "file_delayed_load"};

} // namespace

void compareHeaders(size_t index, const openvdb::GridBase& a, const openvdb::GridBase& b, std::vector<std::string>& out) {
    const std::string prefix = "grid " + std::to_string(index) + " '" + a.getName() + "': ";
    if (a.getName() != b.getName()) out.push_back(prefix + "name differs ('" + a.getName() + "' vs '" + b.getName() + "')");
    if (a.getGridClass() != b.getGridClass())
        out.push_back(prefix + "class differs (" + openvdb::GridBase::gridClassToString(a.getGridClass()) + " vs " +
                      openvdb::GridBase::gridClassToString(b.getGridClass()) + ")");
    if (a.transform() != b.transform()) out.push_back(prefix + "transform differs");
    std::set<std::string> names;
    for (auto it = a.beginMeta(); it != a.endMeta(); ++it) names.insert(it->first);
    for (auto it = b.beginMeta(); it != b.endMeta(); ++it) names.insert(it->first);
    for (const std::string& name : names) {
        if (kWriterMetadata.count(name)) continue;
        const auto ma = a[name], mb = b[name];
        if (!ma || !mb) out.push_back(prefix + "metadata '" + name + "' only in " + (ma ? "the first" : "the second"));
        else if (!(*ma == *mb)) out.push_back(prefix + "metadata '" + name + "' differs (" + ma->str() + " vs " + mb->str() + ")");
    }
}

void compareFileMetadata(const openvdb::MetaMap& a, const openvdb::MetaMap& b, std::vector<std::string>& out) {
    std::set<std::string> names;
    for (auto it = a.beginMeta(); it != a.endMeta(); ++it) names.insert(it->first);
    for (auto it = b.beginMeta(); it != b.endMeta(); ++it) names.insert(it->first);
    for (const std::string& name : names) {
        const auto ma = a[name], mb = b[name];
        if (!ma || !mb) out.push_back("file metadata '" + name + "' only in " + (ma ? "the first" : "the second"));
        else if (ma->typeName() != mb->typeName() || !(*ma == *mb))
            out.push_back("file metadata '" + name + "' differs (" + ma->str() + " vs " + mb->str() + ")");
    }
}

} // namespace vdbdag::bridge::detail
