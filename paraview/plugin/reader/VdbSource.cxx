// VolumeSource of a .vdb file: vdb_bridge's checked reading (VdbFile.h: the
// file's layout verified before OpenVDB reads it, grids in file order), then
// OpenVDB's delayed loading (leaf buffers are read from the mapped file when
// a sample first falls in them). Grids of the nine value types vdbdag converts are listed; others
// (points, strings) are left out, and a grid whose transform is not linear
// is refused.
#include "VolumeSource.h"

#include <openvdb/openvdb.h>

#include "vdb_bridge/detail/VdbFile.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace
{
// Calls f with grid g as its own type; false for a type not read here.
template <typename F>
bool withTypedGrid(const openvdb::GridBase& g, F&& f)
{
  if (g.isType<openvdb::FloatGrid>())
    f(static_cast<const openvdb::FloatGrid&>(g), "float");
  else if (g.isType<openvdb::DoubleGrid>())
    f(static_cast<const openvdb::DoubleGrid&>(g), "double");
  else if (g.isType<openvdb::Int32Grid>())
    f(static_cast<const openvdb::Int32Grid&>(g), "int32");
  else if (g.isType<openvdb::Int64Grid>())
    f(static_cast<const openvdb::Int64Grid&>(g), "int64");
  else if (g.isType<openvdb::BoolGrid>())
    f(static_cast<const openvdb::BoolGrid&>(g), "bool");
  else if (g.isType<openvdb::MaskGrid>())
    f(static_cast<const openvdb::MaskGrid&>(g), "mask");
  else if (g.isType<openvdb::Vec3SGrid>())
    f(static_cast<const openvdb::Vec3SGrid&>(g), "vec3s");
  else if (g.isType<openvdb::Vec3DGrid>())
    f(static_cast<const openvdb::Vec3DGrid&>(g), "vec3d");
  else if (g.isType<openvdb::Vec3IGrid>())
    f(static_cast<const openvdb::Vec3IGrid&>(g), "vec3i");
  else
    return false;
  return true;
}

template <typename Visit>
void forEachSample(const vdbdag::IndexBBox& box, uint64_t stride, Visit&& visit)
{
  const std::array<uint64_t, 3> dims = vdbdag::sampleDims(box, stride);
  vdbdag::sampleCount(box, stride); // refuses a count past 2^62
  for (uint64_t z = 0; z < dims[2]; ++z)
    for (uint64_t y = 0; y < dims[1]; ++y)
      for (uint64_t x = 0; x < dims[0]; ++x)
      {
        const int64_t c[3] = { box.min[0] + int64_t(x * stride), box.min[1] + int64_t(y * stride), box.min[2] + int64_t(z * stride) };
        const bool inside = c[0] >= INT32_MIN && c[0] <= INT32_MAX && c[1] >= INT32_MIN && c[1] <= INT32_MAX && c[2] >= INT32_MIN &&
          c[2] <= INT32_MAX;
        visit(openvdb::Coord(int32_t(c[0]), int32_t(c[1]), int32_t(c[2])), inside);
      }
}

class VdbSource : public VolumeSource
{
public:
  explicit VdbSource(const std::string& path)
  {
    // The file's layout is checked before OpenVDB walks it (a forged or cut
    // file is refused, naming it); then each grid is read with delayed
    // loading, in file order.
    const vdbdag::bridge::detail::VdbFileIndex index = vdbdag::bridge::detail::indexVdbFile(path);
    for (const std::string& uniqueName : index.uniqueNames)
    {
      const openvdb::GridBase::Ptr g = vdbdag::bridge::detail::readGridDelayed(path, uniqueName);
      VolumeGrid facts;
      facts.name = g->getName();
      const bool known = withTypedGrid(*g, [&](const auto& grid, const char* type) {
        using Value = typename std::decay_t<decltype(grid)>::ValueType;
        facts.type = type;
        facts.valueSize = facts.type == "mask" ? 0u : (facts.type == "bool" ? 1u : unsigned(sizeof(Value)));
      });
      if (!known)
        continue;
      const openvdb::math::MapBase::ConstPtr map = g->transform().baseMap();
      if (!map->isLinear())
        throw std::runtime_error(path + ": grid '" + facts.name + "' has a non-linear (" + map->type() + ") transform");
      const openvdb::Mat4d m = map->getAffineMap()->getMat4();
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
          facts.indexToWorld[size_t(4 * r + c)] = m(r, c);
      const openvdb::CoordBBox b = g->evalActiveVoxelBoundingBox();
      if (!b.empty())
        for (int a = 0; a < 3; ++a)
        {
          facts.box.min[size_t(a)] = b.min()[a];
          facts.box.max[size_t(a)] = b.max()[a];
        }
      this->Grids.push_back(facts);
      this->VdbGrids.push_back(g);
    }
  }

  void sample(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, void* out) const override
  {
    auto* bytes = static_cast<uint8_t*>(out);
    withTypedGrid(*this->VdbGrids.at(g), [&](const auto& grid, const char*) {
      using Value = typename std::decay_t<decltype(grid)>::ValueType;
      auto accessor = grid.getConstAccessor();
      forEachSample(box, stride, [&](const openvdb::Coord& c, bool inside) {
        if constexpr (std::is_same_v<Value, openvdb::ValueMask>)
          *bytes++ = inside && accessor.isValueOn(c) ? 1 : 0;
        else if constexpr (std::is_same_v<Value, bool>)
          *bytes++ = (inside ? accessor.getValue(c) : grid.background()) ? 1 : 0;
        else
        {
          const Value v = inside ? accessor.getValue(c) : grid.background();
          std::memcpy(bytes, &v, sizeof(Value));
          bytes += sizeof(Value);
        }
      });
    });
  }

  void sampleActive(size_t g, const vdbdag::IndexBBox& box, uint64_t stride, uint8_t* out) const override
  {
    withTypedGrid(*this->VdbGrids.at(g), [&](const auto& grid, const char*) {
      auto accessor = grid.getConstAccessor();
      forEachSample(box, stride, [&](const openvdb::Coord& c, bool inside) { *out++ = inside && accessor.isValueOn(c) ? 1 : 0; });
    });
  }

  void forEachActive(size_t g, const vdbdag::IndexBBox& box, const vdbdag::Grid::ActiveVisitor& visit) const override
  {
    if (box.empty())
      return;
    auto clamp = [](int64_t v) { return int32_t(std::max<int64_t>(INT32_MIN, std::min<int64_t>(INT32_MAX, v))); };
    const openvdb::CoordBBox region(openvdb::Coord(clamp(box.min[0]), clamp(box.min[1]), clamp(box.min[2])),
      openvdb::Coord(clamp(box.max[0]), clamp(box.max[1]), clamp(box.max[2])));
    withTypedGrid(*this->VdbGrids.at(g), [&](const auto& grid, const char*) {
      using Value = typename std::decay_t<decltype(grid)>::ValueType;
      // The value's bytes as VolumeSource gives them (bool: one byte; mask: none).
      auto bytesOf = [](const Value& v, uint8_t* out) -> const void* {
        if constexpr (std::is_same_v<Value, openvdb::ValueMask>)
          return nullptr;
        else if constexpr (std::is_same_v<Value, bool>)
        {
          out[0] = v ? 1 : 0;
          return out;
        }
        else
        {
          std::memcpy(out, &v, sizeof(Value));
          return out;
        }
      };
      uint8_t value[24] = {};
      for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
      {
        if (!leaf->getNodeBoundingBox().hasOverlap(region))
          continue;
        for (auto v = leaf->cbeginValueOn(); v; ++v)
        {
          const openvdb::Coord c = v.getCoord();
          if (region.isInside(c) && !visit({ c.x(), c.y(), c.z() }, 0, bytesOf(*v, value)))
            return;
        }
      }
      auto tiles = grid.tree().cbeginValueOn();
      tiles.setMaxDepth(std::decay_t<decltype(tiles)>::LEAF_DEPTH - 1);
      for (; tiles; ++tiles)
      {
        if (tiles.isVoxelValue())
          continue;
        const openvdb::CoordBBox b = tiles.getBoundingBox();
        if (!b.hasOverlap(region))
          continue;
        const unsigned log2 = unsigned(openvdb::util::FindHighestOn(uint32_t(b.dim().x())));
        if (!visit({ b.min().x(), b.min().y(), b.min().z() }, log2, bytesOf(*tiles, value)))
          return;
      }
    });
  }

private:
  std::vector<openvdb::GridBase::Ptr> VdbGrids;
};
} // namespace

std::unique_ptr<VolumeSource> openVdbSource(const std::string& path)
{
  return std::make_unique<VdbSource>(path);
}
