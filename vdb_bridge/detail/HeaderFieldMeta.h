// Source header fields (DenseVolume::headerFields) to and from a grid's
// OpenVDB metadata: int64 as Int64Metadata, double as DoubleMetadata,
// strings as StringMetadata, under the field's own key.
#pragma once
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/NiftiFields.h"

namespace vdbdag::bridge::detail {

inline void insertHeaderFields(openvdb::MetaMap& meta, const std::vector<HeaderField>& fields) {
    for (const HeaderField& f : fields) {
        if (const auto* i = std::get_if<int64_t>(&f.value)) meta.insertMeta(f.key, openvdb::Int64Metadata(*i));
        else if (const auto* d = std::get_if<double>(&f.value)) meta.insertMeta(f.key, openvdb::DoubleMetadata(*d));
        else meta.insertMeta(f.key, openvdb::StringMetadata(std::get<std::string>(f.value)));
    }
}

// The fields whose keys start with `prefix` ("nifti_"); other kinds of
// metadata under such a key are left out.
inline HeaderFieldMap headerFieldsWithPrefix(const openvdb::MetaMap& meta, const std::string& prefix) {
    HeaderFieldMap out;
    for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it) {
        if (it->first.rfind(prefix, 0) != 0 || !it->second) continue;
        if (auto i = openvdb::DynamicPtrCast<openvdb::Int64Metadata>(it->second)) out[it->first] = int64_t(i->value());
        else if (auto d = openvdb::DynamicPtrCast<openvdb::DoubleMetadata>(it->second)) out[it->first] = d->value();
        else if (auto s = openvdb::DynamicPtrCast<openvdb::StringMetadata>(it->second)) out[it->first] = s->value();
    }
    return out;
}

} // namespace vdbdag::bridge::detail
