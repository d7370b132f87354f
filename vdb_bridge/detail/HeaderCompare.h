// Private: the header parts of a comparison (VdbCompare.h, VdbStreamCompare.h):
// a grid's name, class, transform and metadata, and the file's metadata,
// each difference a line of `out`. Not to be included outside vdb_bridge/.
#pragma once
#include <sstream>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

namespace vdbdag::bridge::detail {

// Grid `index` of the first file against the same grid of the second.
void compareHeaders(size_t index, const openvdb::GridBase& a, const openvdb::GridBase& b, std::vector<std::string>& out);

// File-level metadata, entry by entry.
void compareFileMetadata(const openvdb::MetaMap& a, const openvdb::MetaMap& b, std::vector<std::string>& out);

// A value for a difference's example line.
template <typename T>
std::string showValue(const T& v) {
    std::ostringstream s;
    s.precision(9);
    s << v;
    return s.str();
}

inline std::string showCoord(const openvdb::Coord& c) {
    return "(" + std::to_string(c.x()) + "," + std::to_string(c.y()) + "," + std::to_string(c.z()) + ")";
}

} // namespace vdbdag::bridge::detail
